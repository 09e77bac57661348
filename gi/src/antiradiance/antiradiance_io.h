#pragma once
// Saving an antiradiance bake (antiradiance_region.h: elements, static links, baseline)
// into a bake bundle and loading it back, with the bundle's checksum and stale rules.
//   gi::save_antiradiance("level.gibake", bake, input);
//   auto bake = gi::load_antiradiance("level.gibake", input);   // checks the geometry hash
//
// Files (DESIGN.md §5, docs/bake-bundle.md):
//   antiradiance.bin  the checksummed container of io/blob_file.h, magic "GIANTIRA", version 4
//                     (version 3 lacked the near-door visibility settings and the element
//                     triangles its rays need; version 2 lacked the refinement settings below, so a load relinked the
//                     door without split leaf links; version 1 stored the links as 16-byte
//                     records. Both are refused by name: re-bake).
//   antiradiance_at_pose.bin  magic "GIANTPOS", version 1: what a load at the baked pose
//                     would compute (AntiradianceBake::AtBakedPose), written by the bake so
//                     the load reads it (absent: the load computes it). Payload:
//       string geometry_hash; uint64 relinked_elements; uint64 link_count;
//       array<uint8> link_frame   the posed links (posed_links), planes as below;
//       uint64 layout_fingerprint (atlas_layout_fingerprint of the blends' atlas, 0: none);
//       uint64 blend_count; array<uint8> blend_frame   one zstd frame of blend_count x 36
//                     bytes: texel (uint32), four leaves (int32, -1: none), four weights
//                     (float32), in increasing texel order
//   manifest.json     methods.antiradiance = {
//     "files":    { "elements": {"file": "antiradiance.bin", "xxh3_64": "<hex of the whole file>"},
//                   "at_pose": {"file": "antiradiance_at_pose.bin", "xxh3_64": ...} },
//     "settings": { AntiradianceSettings' fields }, "elements", "leaves", "static_links",
//     "deforming_instances", "memory": { "file_bytes" } }
// The bake depends on the geometry and the materials (element albedos) and on the static
// lights (the baseline's direct light), so the geometry hash of the manifest makes it stale
// like every other file; a light edit needs a re-bake (docs/antiradiance.md).
//
// antiradiance.bin payload (little-endian; "array" = uint64 count then the elements;
// vec3 = 3 x float32, mat4 = 16 x float32 column-major):
//   string   geometry_hash                 uint64 length + chars
//   int32 bins_per_side, float32 patch_size_m, float32 exchange_radius_m, float32 oracle_scale,
//   int32 iterations, int32 antiradiance_steps, uint8 scheme, float64 residual_tolerance,
//   int32 growth_limit, int32 area_light_samples, uint64 seed,
//   float32 near_patch_size_m, float32 near_radius_m, int32 leaf_link_pieces,
//   uint8 near_visibility (0/1), float32 near_visibility_radius_m,
//   int32 near_visibility_point_pairs, uint64 near_visibility_budget_bytes   AntiradianceSettings
//   array<uint32> deforming_instances      BakeInput instance of each deforming group
//   array<mat4>   group_transform          the pose each group was baked at
//   array<node>   nodes                    ElementNode, 18 x 4 bytes: center vec3, radius,
//                                          normal vec3, area, albedo vec3, parent, first_child,
//                                          child_count, leaf_begin, leaf_end, group, end (int32s)
//   array<int32>  children, leaves, group_root, node_instance
//   array<vec3>   object_center, object_normal;  array<float32> object_radius, object_area
//   array<vec3>   corners, object_corners  each element's triangle (3 per element, world at the
//                                          baked pose and object space; zeros for clusters);
//                                          empty unless near_visibility (the runtime's rays)
//   uint64        link_count               the static links, sorted by (receiver, bin, sender)
//   array<uint8>  link_frame               one zstd frame of link_count x 14 bytes, lossless planes:
//                                          receiver - previous receiver (uint32), bin (uint16),
//                                          sender - previous sender within a (receiver, bin) run
//                                          else sender (uint32), then the form factor's float32
//                                          bits as four byte planes (low byte first)
//   array<vec3>   baseline                 one per leaf
// Nothing follows (trailing bytes are an error). The reader checks every index against the
// arrays it points into, every value for NaN/infinity, and the sizes against each other.

#include <engine/result.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "antiradiance/antiradiance_region.h"
#include "io/blob_file.h"

namespace gi {

inline constexpr const char* kAntiradianceMethod = "antiradiance";
inline constexpr const char* kAntiradianceFile = "antiradiance.bin";
inline constexpr BlobMagic kAntiradianceMagic{"GIANTIRA"};
inline constexpr std::uint32_t kAntiradianceVersion = 5;
/// What the bake computed for a load at its pose (AntiradianceBake::AtBakedPose).
inline constexpr const char* kAntiradianceAtPoseFile = "antiradiance_at_pose.bin";
inline constexpr BlobMagic kAntiradianceAtPoseMagic{"GIANTPOS"};
inline constexpr std::uint32_t kAntiradianceAtPoseVersion = 1;

/// What antiradiance.bin holds.
struct AntiradianceFile {
  std::string geometry_hash;
  AntiradianceBake bake;
};

/// Writes `bake` to `path` atomically. Error (naming the file, writing nothing) when the
/// bake is inconsistent (see read_antiradiance's checks).
engine::Status write_antiradiance(const std::filesystem::path& path, const AntiradianceBake& bake,
                                  const std::string& geometry_hash);
/// Reads and checks antiradiance.bin (container, complete fields, sizes, indices, values).
engine::Result<AntiradianceFile> read_antiradiance(const std::filesystem::path& path);

/// What antiradiance_at_pose.bin holds.
struct AntiradianceAtPoseFile {
  std::string geometry_hash;
  AntiradianceBake::AtBakedPose at_baked_pose;
};

/// Writes bake.at_baked_pose to `path` atomically. Error (naming the file, writing nothing)
/// when the bake has none or it does not fit the bake's hierarchy.
engine::Status write_antiradiance_at_pose(const std::filesystem::path& path, const AntiradianceBake& bake,
                                          const std::string& geometry_hash);
/// Reads antiradiance_at_pose.bin (container, complete fields, zstd streams of the sizes the
/// counts give). Its indices are checked against the bake by load_antiradiance.
engine::Result<AntiradianceAtPoseFile> read_antiradiance_at_pose(const std::filesystem::path& path);

/// Writes antiradiance.bin into `bundle_dir` (created if needed) and the manifest's
/// "antiradiance" entry (other methods' entries kept when the geometry hash is the same).
engine::Status save_antiradiance(const std::filesystem::path& bundle_dir, const AntiradianceBake& bake,
                                 const BakeInput& input);
/// Loads the bake of `bundle_dir` for `input`: rejects a stale bundle (the message says
/// "stale" and names both hashes), checks the file against the manifest's checksum, reads it.
/// Every error names the file and the problem.
engine::Result<AntiradianceBake> load_antiradiance(const std::filesystem::path& bundle_dir, const BakeInput& input);

/// Distributed bakes (docs/distributed-bake.md): a shard's links (link_elements_shard), sorted,
/// as one zstd frame of the link planes antiradiance.bin stores. Errors name `path`.
engine::Result<std::vector<std::uint8_t>> pack_link_shard(const std::filesystem::path& path,
                                                          const std::vector<Link>& links);
/// The links of pack_link_shard's frame, which must hold exactly `link_count` of them.
/// Errors name `path`: a corrupt frame, another size.
engine::Result<std::vector<Link>> unpack_link_shard(const std::filesystem::path& path,
                                                    std::span<const std::uint8_t> frame, std::uint64_t link_count);

}  // namespace gi
