#pragma once
// The shard file of a distributed bake (docs/distributed-bake.md): what `gi-bake --shard
// I/N` computed of the sharded methods (light atlas, PRM, antiradiance links), checksummed like every bake file
// (io/blob_file.h, magic "GISHARD1"), with what the merge checks it against: the scene's
// geometry and static-lights hashes, the bake settings' hash, the seed, I and N, and the
// method list the shard's plan called for.
//   auto file = gi::read_shard_file(dir / gi::shard_file_name(3, 7));  // errors name the file

#include <engine/result.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "light_atlas/light_atlas.h"
#include "prm/prm.h"

namespace gi {

/// A shard's antiradiance links (link_elements_shard: the links to the receivers of its
/// blocks of 64 elements) as antiradiance_io's pack_link_shard frame.
struct AntiradianceShardPart {
  std::uint64_t links = 0;
  std::vector<std::uint8_t> frame;
};

struct ShardFile {
  std::uint32_t index = 0;
  std::uint32_t count = 1;
  std::string geometry_hash;  ///< scene_geometry_hash of the input.
  std::string lights_hash;    ///< static_lights_hash of the input.
  std::string settings_hash;  ///< Of the BakeOptions that change the result (not threads).
  std::uint64_t seed = 1;
  std::vector<std::string> methods;  ///< Every method of the bake (the merge bakes the others).
  std::optional<LightAtlasShardPart> atlas;
  std::optional<PrmShardPart> prm;
  std::optional<AntiradianceShardPart> antiradiance;
};

/// Writes `file` atomically (write_blob). Errors name `path`.
engine::Status write_shard_file(const std::filesystem::path& path, const ShardFile& file);

/// Reads a shard file. Errors name the file and the check that failed: missing, truncated,
/// damaged (checksum), wrong magic or version, inconsistent arrays.
engine::Result<ShardFile> read_shard_file(const std::filesystem::path& path);

}  // namespace gi
