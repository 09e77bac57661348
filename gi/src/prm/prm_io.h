#pragma once
// Saving a baked PRM (precomputed radiance maps) into a bake bundle and loading it back.
//   gi::save_prm("level.gibake", prm, input);
//   auto prm = gi::load_prm("level.gibake", input);   // checks the geometry hash
//
// Files (DESIGN.md §5, docs/bake-bundle.md):
//   prm_panes.bin   the checksummed container of bake/blob_file.h, magic "GIPRMPAN", version 3.
//   manifest.json   methods.prm = {
//     "files":        { "panes": {"file": "prm_panes.bin", "xxh3_64": "<hex of the whole file>"},
//                       "layout": the pane layout (prm_layout.bin),
//                       "atlas_layout": coarse panes only, the light atlas's layout (prm_atlas_layout.bin) },
//     "settings":     { PrmSettings' scalar fields but threads and progress (pane_tile_texels and
//                       pane_threshold included) },
//     "layout":       { "requested_texels_per_metre", "texels_per_metre", "padding_texels", "width", "height" }
//                       of the pane layout,
//     "atlas_layout": the same of the light atlas's layout (coarse panes only: pane_texels_per_metre > 0
//                       and below texels_per_metre; load builds the PaneUpsampler from the two layouts),
//     "entry_points", "clusters", "pane_texels",
//     "stats":        { PrmStats' counts (timings: bake_stats.json) },
//     "memory":       { "pane_bytes_half": stored block elements x 3 x 2 (the panes as GPU halves),
//                       "pane_blocks": blocks stored over all clusters,
//                       "file_bytes": size of prm_panes.bin } }
// The PRM depends on the static geometry and materials only (entry points stand for any
// light), so there is no lights hash: moving or editing lights never makes it stale.
//
// prm_panes.bin payload (little-endian; "array" = uint64 count then the elements;
// vec3 = 3 x float32):
//   string        geometry_hash        uint64 length + chars: the scene the PRM belongs to
//   float32 texels_per_metre, float32 pane_texels_per_metre, int32 entry_points, int32 clusters, float32 splitting,
//   int32 max_path_nodes, uint8 kmeans, uint64 seed
//                                      PrmSettings' scalar fields (not threads: no file depends on them)
//   int32 width, int32 height          atlas size (the layout is rebuilt from the scene)
//   int32 cluster_count
//   array<uint32> texels               ascending atlas texel indices, each < width x height
//   array<vec3> entry_position, array<vec3> entry_normal, array<float32> entry_area_m2,
//   array<uint32> entry_cluster        the entry points (one element per entry in each)
//   array<uint32> cluster_size         cluster_count elements, members per cluster
//   int32 tile_texels, float32 threshold
//                                      the blocks (prm_panes.h): tiles of tile_texels^2 atlas texels
//   array<uint32> cluster_first        cluster_count + 1 elements: pane c's blocks are
//                                      blocks[cluster_first[c] .. cluster_first[c + 1])
//   array<uint32> blocks               tile index of each stored block (prm_tiles order), ascending per pane
//   array<float32> pane_scale          cluster_count elements, power-of-two scale s_c per pane
//   uint64 pane_half_bytes             stored block elements x 3 x 2: the decompressed size
//   array<uint8> panes_zstd            one zstd frame (content size and checksum recorded)
// Nothing follows (trailing bytes are an error). The zstd frame decompresses to the stored
// values as IEEE binary16 values h = half(v / s_c) in PrmPanes::values' order (block by
// block, a block's elements in tile order, channel ch), split into two byte planes: every
// half's low byte, then every high byte (smooth panes then give long runs in the high-byte
// plane, which zstd packs well).
//
// Precision. s_c = 2^(e - 15) where the pane's largest value is m x 2^e (m in [0.5, 1)), so
// the largest value maps into [2^14, 2^15) — well inside the half range (65504), whatever
// the pane's magnitude — and s_c is a power of two, so scaling is exact. The only rounding
// is float -> half, round to nearest even: a decoded value v' = float(h) x s_c satisfies
//   |v' - v| <= 2^-11 |v| + 2^-39 max_c        (2^-11 ~ 4.9e-4, 2^-39 ~ 1.8e-12)
// where max_c is the pane's largest value: relative 4.9e-4 down to ~1.9e-9 max_c (half
// normals), absolute 1.8e-12 max_c below. Exact zeros stay zero. A pane of zeros has s_c = 1.

#include <engine/result.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "io/blob_file.h"
#include "prm/prm.h"

namespace gi {

inline constexpr const char* kPrmMethod = "prm";
inline constexpr const char* kPrmPanesFile = "prm_panes.bin";
/// The PRM's atlas layout (bundle/atlas_layout_file.h), files.layout.
inline constexpr const char* kPrmLayoutFile = "prm_layout.bin";
/// Coarse panes only: the light atlas's layout they are read at, files.atlas_layout.
inline constexpr const char* kPrmAtlasLayoutFile = "prm_atlas_layout.bin";
inline constexpr const char* kPrmAtlasLayoutKey = "atlas_layout";
inline constexpr BlobMagic kPrmPanesMagic{"GIPRMPAN"};
// 2: the thread count left out (a bundle does not depend on it; bake_stats.json says it).
// 3: sparse panes, stored per atlas tile only where the cluster's light reaches (issue 38).
// 4: pane_texels_per_metre (panes coarser than the atlas, read through a PaneUpsampler).
inline constexpr std::uint32_t kPrmPanesVersion = 4;

/// Relative and pane-relative bounds of the half-float pane storage (see above).
inline constexpr double kPrmPaneRelativeError = 1.0 / 2048.0;               // 2^-11
inline constexpr double kPrmPaneAbsoluteErrorOfMax = 1.0 / 549755813888.0;  // 2^-39

/// What prm_panes.bin holds: a Prm without its layout (rebuilt from the scene) and stats
/// (kept in the manifest).
struct PrmPaneFile {
  std::string geometry_hash;
  Prm prm;  ///< layout and stats left default; width/height set.
};

/// Writes `prm`'s settings, entry points, clusters and panes (as scaled halves, zstd
/// compressed) to `path` atomically. Error, naming the file, writing nothing, when the Prm
/// is inconsistent (sizes, texel order and range, clusters) or holds a NaN, infinite or
/// negative pane value.
engine::Status write_prm_panes(const std::filesystem::path& path, const Prm& prm, const std::string& geometry_hash);

/// Reads and checks prm_panes.bin: the container (magic, version, size, checksum), complete
/// fields, the zstd frame and its decompressed size, consistent sizes, ascending in-range
/// texels, clusters in range, finite non-negative values.
engine::Result<PrmPaneFile> read_prm_panes(const std::filesystem::path& path);

/// Writes prm_panes.bin into `bundle_dir` (created if needed), then the manifest's "prm"
/// entry (other methods' entries kept when the manifest has the same geometry hash). Error
/// when the Prm is inconsistent (see write_prm_panes) or a file cannot be written.
engine::Status save_prm(const std::filesystem::path& bundle_dir, const Prm& prm, const BakeInput& input);

/// Loads the PRM of `bundle_dir` for `input`: rejects a stale bundle (geometry hash differs
/// from scene_geometry_hash(input); the message says "stale" and names both hashes), checks
/// the file against the manifest's checksum, reads it (read_prm_panes), rebuilds the layout
/// from atlas_inputs_from(input) with the manifest's requested density and padding and
/// checks its size. Every error names the file and the problem.
engine::Result<Prm> load_prm(const std::filesystem::path& bundle_dir, const BakeInput& input);

/// Float -> IEEE binary16, round to nearest even (overflow gives infinity, NaN stays NaN).
std::uint16_t float_to_half(float v);
/// IEEE binary16 -> float (exact).
float half_to_float(std::uint16_t h);

}  // namespace gi
