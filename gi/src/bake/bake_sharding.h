#pragma once
// Distributed bakes (docs/distributed-bake.md): `gi-bake --shard I/N` bakes shard I of the
// sharded methods (light atlas, PRM, antiradiance links) into its shard file beside the
// bundle; `gi-bake --merge` reads every shard file back, checked against this scene and
// these options, for bake_bundle to bake the bundle from.
//   auto report = gi::bake_shard(input, dir, options, host, methods, {});  // gi-bake --shard I/N
//   auto parts = gi::read_shards(input, dir, options, methods, host);     // gi-bake --merge

#include <engine/result.h>
#include <gi/bake.h>

#include <filesystem>
#include <string>
#include <vector>

#include "antiradiance/link_mesh.h"
#include "light_atlas/light_atlas.h"
#include "prm/prm.h"

namespace gi {

/// The shards' parts a merge bakes the sharded methods from, in shard order.
struct MergedParts {
  std::vector<LightAtlasShardPart> atlas;
  std::vector<PrmShardPart> prm;
  std::vector<std::vector<Link>> antiradiance;  ///< Each shard's links, unpacked.
};

/// Bakes shard options.shard_index of options.shard_count of `methods` into
/// shard_directory(bundle_dir) / shard_file_name(I, N); `report` gains one entry per
/// sharded method (its bytes: the shard file's).
engine::Result<BakeReport> bake_shard(const BakeInput& input, const std::filesystem::path& bundle_dir,
                                      const BakeOptions& options, const BakeHost& host,
                                      const std::vector<std::string>& methods, BakeReport report);

/// Every shard file beside the bundle, checked (present once each, of this scene and these
/// options), its parts in shard order. Errors name the shard file.
engine::Result<MergedParts> read_shards(const BakeInput& input, const std::filesystem::path& bundle_dir,
                                        const BakeOptions& options, const std::vector<std::string>& methods,
                                        const BakeHost& host);

}  // namespace gi
