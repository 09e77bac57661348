#pragma once
// Saving baked basis radiance fields (Iwasaki et al.) into a bake bundle and loading them
// back, one file per distinct dynamic mesh.
//   gi::save_brf("level.gibake", bake, input);
//   auto brf = gi::load_brf("level.gibake", scene);   // checks every mesh's hash
//
// Files (DESIGN.md §5, docs/bake-bundle.md):
//   brf_<name>.bin  the checksummed container of bake/blob_file.h, magic "GIBRFMSH", version 2;
//                   <name> is BrfSource::name ([A-Za-z0-9_-], unique in the scene).
//   manifest.json   methods.brf = {
//     "files":    { "<name>": {"file": "brf_<name>.bin", "xxh3_64": "<hex of the whole file>"}, ... },
//     "settings": { "basis": { PcaBasisSettings' fields }, "field": { RadianceFieldSettings' fields } },
//     "meshes":   { "<name>": { "mesh_hash", "mesh_index", "entities", "vertices", "basis_requested",
//                               "basis_kept", "condition", "glossy_terms" (0: diffuse), "glossy_brdf_error",
//                               "field_bytes" (raw float32 coefficients),
//                               "field_compressed_bytes" (their zstd frame), "file_bytes" }, ... } }
// Timings and thread counts are not in the bundle's files: bake_stats.json (gi/bake.h) has them.
// A BRF depends on its mesh only (object space), not on the static world or the lights, so
// the scene's geometry hash is not checked on load (it covers static nodes only anyway);
// each file's mesh hash is, against the scene's mesh (gi::brf_mesh_hash).
//
// brf_<name>.bin payload (little-endian; "array" = uint64 count then the elements;
// "string" = uint64 length then the characters; vec3 = 3 x float32):
//   string         name                BrfSource::name (must match the manifest key)
//   string         mesh_hash           16 hex digits, brf_mesh_hash of the mesh baked
//   -- the PCA basis (BrfBasis) --
//   uint64         vertex_count        V >= 1
//   int32          basis_count         N, 1..1024
//   float64        condition           of A over the kept eigenvalues, finite, >= 1
//   vec3           centre              bounding sphere (object space, metres)
//   float32        radius              > 0
//   array<float32> psi                 N x V, psi[i * V + j] = Psi_i(x_j)
//   array<float32> a_inverse           N x N, row-major
//   array<float32> singular_values     descending, at most 65536
//   int32          terms               K it was trained on: 1 + glossy terms
//   -- the basis radiance field (BasisRadianceField) --
//   int32 spheres (1..256), int32 face_resolution (1..256), int32 sh_bands (3 or 4),
//   int32 basis_count (= N), int32 terms (= K)
//   vec3           centre
//   float32        inner_radius, float32 outer_radius     0 < inner <= outer
//   uint64         coefficient_bytes   S x 6 x R^2 x K x N x B^2 x 4: the raw float32 size
//   array<uint8>   coefficients_zstd   one zstd frame (content size and checksum recorded)
//   -- the glossy separation (BrdfSeparation), for a glossy mesh --
//   int32          glossy_terms        0: diffuse, nothing follows; else 1..15 and:
//   float32 f0, float32 alpha, int32 resolution (4..64), float32 relative_error
//   array<float32> g, h                glossy_terms x resolution^2 each
//   array<float32> lobe_sh             glossy_terms x 16
//   array<float32> singular_values     at most 4096
// Nothing follows (trailing bytes are an error). The frame decompresses to the coefficients
// in BasisRadianceField::coefficients' order, as float32 split into four byte planes (every
// value's byte 0, then every byte 1, 2, 3): lossless, so a load is bit-exact, and the
// exponent plane of smooth data packs well. Every float in the file must be finite.

#include <engine/result.h>
#include <engine/scene.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "brf/brf_bake.h"
#include "brf/brf_mesh.h"
#include "io/blob_file.h"

namespace gi {

inline constexpr const char* kBrfMethod = "brf";
inline constexpr BlobMagic kBrfMeshMagic{"GIBRFMSH"};
inline constexpr std::uint32_t kBrfMeshVersion = 2;

/// A scene's BRF bake: the settings and one BrfMeshBake per dynamic mesh.
struct BrfBake {
  BrfSettings settings;
  std::vector<BrfMeshBake> meshes;
};

/// "brf_<mesh_name>.bin".
std::string brf_file_name(const std::string& mesh_name);

/// Writes one mesh's bake to `path` atomically. `compressed_bytes`, when given, receives
/// the size of the coefficients' zstd frame. Error, naming the file, writing nothing, when
/// the bake is inconsistent (sizes, settings out of range) or holds a NaN or infinity.
engine::Status write_brf_mesh(const std::filesystem::path& path, const BrfMeshBake& bake,
                              std::uint64_t* compressed_bytes = nullptr);

/// Reads and checks one brf_<name>.bin: the container (magic, version, size, checksum),
/// complete fields, nothing after them, sizes in range and consistent, the zstd frame and
/// its size, finite values. The timings are left 0 (they live in the manifest) and the
/// model's mesh empty (the file does not hold it: load_brf fills it in).
engine::Result<BrfMeshBake> read_brf_mesh(const std::filesystem::path& path);

/// Writes every mesh's file into `bundle_dir` (created if needed), then the manifest's
/// "brf" entry (other methods' entries kept when the manifest has the same geometry hash,
/// scene_geometry_hash(input)). Everything is checked before anything is written. Errors:
/// an inconsistent bake, two meshes of one name, a file that cannot be written.
engine::Status save_brf(const std::filesystem::path& bundle_dir, const BrfBake& bake, const BakeInput& input);

/// Loads the bake of each of `sources` (result meshes[i] belongs to sources[i]): its
/// manifest entry, the file's checksum against the manifest, read_brf_mesh, then the mesh
/// hash against sources[i].mesh_hash (a differing one is a stale bake: the message says
/// "stale" and names both hashes) and the vertex count; each model's mesh is then
/// sources[i].mesh, what it was baked on. Timings come from the manifest.
/// Every error names the file and the problem.
engine::Result<BrfBake> load_brf(const std::filesystem::path& bundle_dir, std::span<const BrfSource> sources);

/// load_brf of dynamic_brf_meshes(input).
engine::Result<BrfBake> load_brf(const std::filesystem::path& bundle_dir, const BakeInput& input);

}  // namespace gi
