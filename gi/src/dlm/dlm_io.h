#pragma once
// Saving baked directional light maps into a bake bundle and loading them back.
//   gi::save_dlm("level.gibake", dlm, input);
//   auto dlm = gi::load_dlm("level.gibake", input);   // checks the geometry hash
//
// Files (docs/bake-bundle.md):
//   dlm.bin         the checksummed container of io/blob_file.h, magic "GIDLMAPS", version 3.
//   manifest.json   methods.dlm = {
//     "files":    { "maps": {"file": "dlm.bin", "xxh3_64": "<hex of the whole file>"} },
//     "settings": { DlmSettings' scalar fields but threads and progress },
//     "layout":   { "requested_texels_per_metre", "texels_per_metre", "padding_texels", "width", "height" },
//     "directions", "texels",
//     "stats":    { DlmStats' counts (timings: bake_stats.json) },
//     "memory":   { "gpu_bytes": texels x directions x 8 (RGB halves padded to 8 bytes) + width x height x 4
//                   (the texel index map), "bytes_per_texel": directions x 6 (stored halves),
//                   "file_bytes": size of dlm.bin } }
// Stale rules: the maps depend on the static geometry, the materials and the static lights:
// the geometry hash covers geometry and materials (bundle/geometry_hash.h); a light edit is
// the light atlas's stale rule too (re-bake both).
//
// dlm.bin payload (little-endian; "array" = uint64 count then the elements; vec3 = 3 x float32):
//   string        geometry_hash
//   float32 texels_per_metre, int32 directions, uint64 photons, float32 splat_radius_texels,
//   float32 glossy_roughness, float32 glossy_roughness_min, int32 max_bounces, int32 area_light_samples, uint64 seed,
//   int32 tangent_frame_bins (0 or 1)  DlmSettings' scalar fields
//                                      (1: directions are on the hemisphere of each texel's tangent frame)
//   int32 width, int32 height          atlas size (the layout is rebuilt from the scene)
//   array<vec3> directions             Omega, N unit vectors
//   array<uint32> texels               ascending atlas texel indices, each < width x height
//   array<float32> bin_scale           N elements, the power-of-two scale s_k of bin k's layer
//   array<uint16> radiance_half        N x texels x 3 IEEE binary16 values h = half(L / s_k),
//                                      in Dlm::radiance's order (bin, element, channel)
// Nothing follows. s_k = 2^(e - 15) where bin k's largest value is m x 2^e (m in [0.5, 1)) as
// the PRM panes (prm_io.h): the only rounding is float -> half, relative 2^-11 (plus 2^-39 of
// the layer's largest value below half normals). A layer of zeros has s_k = 1.

#include <engine/result.h>
#include <gi/bake_input.h>

#include <filesystem>
#include <string>

#include "dlm/dlm.h"
#include "io/blob_file.h"

namespace gi {

inline constexpr const char* kDlmMethod = "dlm";
inline constexpr const char* kDlmFile = "dlm.bin";
/// The DLM's atlas layout (bundle/atlas_layout_file.h), files.layout.
inline constexpr const char* kDlmLayoutFile = "dlm_layout.bin";
inline constexpr BlobMagic kDlmMagic{"GIDLMAPS"};
/// 2: the bins are the nearest psi's at every normal (no folding at the horizon) and the
/// settings hold glossy_roughness_min. 3: tangent_frame_bins (the renderer reads bins in each
/// texel's tangent frame; the presets bake them). Older versions are refused (re-bake).
inline constexpr std::uint32_t kDlmVersion = 3;
inline constexpr double kDlmRelativeError = 1.0 / 2048.0;

/// What dlm.bin holds: a Dlm without its layout (rebuilt from the scene) and stats.
struct DlmFile {
  std::string geometry_hash;
  Dlm dlm;
};

/// Writes dlm.bin atomically. Error naming the file, writing nothing, when the Dlm is
/// inconsistent or holds a NaN, infinite or negative value.
engine::Status write_dlm_file(const std::filesystem::path& path, const Dlm& dlm, const std::string& geometry_hash);

/// Reads and checks dlm.bin: container, complete fields, sizes, unit directions, ascending
/// in-range texels, power-of-two scales, finite non-negative values.
engine::Result<DlmFile> read_dlm_file(const std::filesystem::path& path);

/// Writes dlm.bin into `bundle_dir`, then the manifest's "dlm" entry.
engine::Status save_dlm(const std::filesystem::path& bundle_dir, const Dlm& dlm, const BakeInput& input);

/// Loads the maps of `bundle_dir` for `input`: stale geometry rejected (the message says
/// "stale"), the file checked against the manifest's checksum and read, the layout rebuilt
/// and compared. Every error names the file and the problem.
engine::Result<Dlm> load_dlm(const std::filesystem::path& bundle_dir, const BakeInput& input);

}  // namespace gi
