#pragma once
// light_atlas_vpls.bin: the VPL solution of a light-atlas bake (kept for incremental
// updates, paper §6.2) and the bake's settings, in the checksummed container of
// bake/blob_file.h with magic "GIVPLSET", version 2.
//   gi::write_light_atlas_vpls(dir / "light_atlas_vpls.bin", bake, hash);
//
// Payload (little-endian; "array" = uint64 count then the elements; vec3 = 3 x float32):
//   string  geometry_hash      (uint64 length + chars) the scene the VPLs belong to
//   float32 texels_per_metre, int32 vpl_count, int32 samples_per_vpl, int32 bounces,
//   float32 unshot_threshold, int32 area_light_samples, uint8 include_direct, uint64 seed
//                                                        LightAtlasSettings' scalar fields (not threads)
//   array<vec3> position, array<vec3> normal, array<vec3> albedo, array<float32> area_m2,
//   array<uint32> sample_first, array<vec3> sample_position, array<vec3> sample_normal,
//   array<float32> sample_area_m2                        VplSet
//   array<vec3> vpl_power
// Nothing follows (trailing bytes are an error).

#include <engine/result.h>

#include <filesystem>
#include <string>

#include "io/blob_file.h"
#include "light_atlas/light_atlas.h"

namespace gi {

inline constexpr BlobMagic kLightAtlasVplsMagic{"GIVPLSET"};
// 2: the thread count left out (a bundle does not depend on it; bake_stats.json says it).
inline constexpr std::uint32_t kLightAtlasVplsVersion = 2;

/// What light_atlas_vpls.bin holds.
struct LightAtlasVplFile {
  std::string geometry_hash;
  LightAtlasSettings settings;  ///< Scalar fields only (no progress callback).
  VplSet vpls;
  std::vector<glm::vec3> vpl_power;
};

/// Writes `bake`'s settings, VPLs and VPL powers atomically. Error when the VPL arrays are
/// inconsistent (sizes, sample ranges), naming the file.
engine::Status write_light_atlas_vpls(const std::filesystem::path& path, const LightAtlasBake& bake,
                                      const std::string& geometry_hash);

/// Reads and checks light_atlas_vpls.bin: the container (magic, version, size, checksum),
/// complete fields, consistent array sizes and sample ranges, finite values.
engine::Result<LightAtlasVplFile> read_light_atlas_vpls(const std::filesystem::path& path);

}  // namespace gi
