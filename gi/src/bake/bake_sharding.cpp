#include "bake/bake_sharding.h"

#include <gi/methods.h>
#include <gi/plan.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <system_error>
#include <utility>

#include "antiradiance/antiradiance_io.h"
#include "antiradiance/antiradiance_region.h"
#include "bake/bake_options.h"
#include "bake/bake_shard.h"
#include "bake/bake_stage.h"
#include "bundle/geometry_hash.h"
#include "bundle/shard_set.h"
#include "core/stopwatch.h"
#include "core/work_shard.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Whether `methods` holds `m`'s key (gi/methods.h).
bool has_key(const std::vector<std::string>& methods, EffectMethod m) {
  return std::find(methods.begin(), methods.end(), method_descriptor(m).key) != methods.end();
}

ShardFile shard_header(const BakeInput& input, const BakeOptions& options, const std::vector<std::string>& methods,
                       std::uint32_t index, std::uint32_t count) {
  ShardFile f;
  f.index = index;
  f.count = count;
  f.geometry_hash = scene_geometry_hash(input);
  f.lights_hash = static_lights_hash(input);
  f.settings_hash = bake_settings_hash(options);
  f.seed = options.seed;
  f.methods = methods;
  return f;
}

engine::Status shard_atlas(const BakeInput& input, const BakeOptions& options, const BakeHost& host, WorkShard shard,
                           ShardFile& file, BakeReport& report) {
  const BakeStage stage{host, "light atlas"};
  auto settings = atlas_settings(options, stage);
  if (!settings) return settings.error();
  const auto start = Clock::now();
  auto part = bake_light_atlas_shard(input, *settings, shard);
  if (!part) return part.error();
  stage.log(format_line("light atlas shard %u/%u: %zu texels gathered, %.2f s", shard.index, shard.count,
                        part->texels.size(), seconds_since(start)));
  report.baked.push_back({std::string(effect_key(EffectMethod::LightAtlas)), seconds_since(start), 0});
  file.atlas = std::move(part).value();
  return {};
}

engine::Status shard_prm(const BakeInput& input, const BakeOptions& options, const BakeHost& host, WorkShard shard,
                         ShardFile& file, BakeReport& report) {
  const BakeStage stage{host, "PRM"};
  auto settings = prm_settings(options, stage);
  if (!settings) return settings.error();
  const auto start = Clock::now();
  auto part = bake_prm_shard(input, *settings, shard);
  if (!part) return part.error();
  stage.log(format_line("PRM shard %u/%u: %zu texels x %d clusters, %.2f s", shard.index, shard.count,
                        part->texels.size(), part->cluster_count, seconds_since(start)));
  report.baked.push_back({std::string(effect_key(EffectMethod::Prm)), seconds_since(start), 0});
  file.prm = std::move(part).value();
  return {};
}

engine::Status shard_antiradiance(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                  const BakeHost& host, WorkShard shard, ShardFile& file, BakeReport& report) {
  const BakeStage stage{host, "antiradiance"};
  const auto start = Clock::now();
  auto links = bake_antiradiance_links_shard(input, antiradiance_settings(options), shard);
  if (!links) return links.error();
  const fs::path path = shard_directory(bundle_dir) / shard_file_name(shard.index, shard.count);
  auto frame = pack_link_shard(path, links->links);
  if (!frame) return frame.error();
  stage.log(format_line("antiradiance shard %u/%u: links of %zu elements, %zu links, %.2f s", shard.index, shard.count,
                        links->relinked_elements, links->links.size(), seconds_since(start)));
  report.baked.push_back({std::string(effect_key(EffectMethod::Antiradiance)), seconds_since(start), 0});
  file.antiradiance = AntiradianceShardPart{.links = links->links.size(), .frame = std::move(frame).value()};
  return {};
}

// Error naming `path` when its shard `file` is not one of this merge's (`expected`, `count`
// shards of `methods`).
engine::Status check_shard(const fs::path& path, const ShardFile& file, const ShardFile& expected, std::uint32_t count,
                           const std::vector<std::string>& methods) {
  const auto foreign = [&](const std::string& what) {
    return engine::Error{path.string(), "", "foreign shard: " + what + "; bake it again with this scene and options"};
  };
  if (file.count != count)
    return foreign("shard " + std::to_string(file.index) + " of " + std::to_string(file.count) + ", the merge is of " +
                   std::to_string(count));
  if (file.geometry_hash != expected.geometry_hash)
    return foreign("baked from other geometry (hash " + file.geometry_hash + ", the scene's " + expected.geometry_hash +
                   ")");
  if (file.lights_hash != expected.lights_hash)
    return foreign("baked under other static lights (hash " + file.lights_hash + ", the scene's " +
                   expected.lights_hash + ")");
  if (file.settings_hash != expected.settings_hash || file.seed != expected.seed)
    return foreign("baked with other settings (settings hash " + file.settings_hash + " seed " +
                   std::to_string(file.seed) + ", this merge's " + expected.settings_hash + " seed " +
                   std::to_string(expected.seed) + ")");
  if (file.methods != expected.methods || file.atlas.has_value() != has_key(methods, EffectMethod::LightAtlas) ||
      file.prm.has_value() != has_key(methods, EffectMethod::Prm) ||
      file.antiradiance.has_value() != has_key(methods, EffectMethod::Antiradiance))
    return foreign("its methods differ from this merge's");
  return {};
}

}  // namespace

fs::path shard_directory(const fs::path& bundle_dir) {
  fs::path dir = bundle_dir;
  if (!dir.has_filename()) dir = dir.parent_path();  // "out/level.gibake/"
  return dir.parent_path() / (dir.filename().string() + ".shards");
}

std::string shard_file_name(std::uint32_t index, std::uint32_t count) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "shard-%04u-of-%04u.gishard", index, count);
  return buf;
}

engine::Result<BakeReport> bake_shard(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                      const BakeHost& host, const std::vector<std::string>& methods,
                                      BakeReport report) {
  const std::uint32_t index = options.shard_index, count = options.shard_count;
  if (index >= count)
    return engine::invalid_request("shard " + std::to_string(index) + "/" + std::to_string(count) +
                                   " does not exist (shards are 0..N-1)");
  ShardFile file = shard_header(input, options, methods, index, count);
  const WorkShard shard{.index = index, .count = count};
  const BakeStage log{host, "shard"};
  if (has_key(methods, EffectMethod::LightAtlas))
    if (auto ok = shard_atlas(input, options, host, shard, file, report); !ok) return ok.error();
  if (has_key(methods, EffectMethod::Prm))
    if (auto ok = shard_prm(input, options, host, shard, file, report); !ok) return ok.error();
  if (has_key(methods, EffectMethod::Antiradiance))
    if (auto ok = shard_antiradiance(input, bundle_dir, options, host, shard, file, report); !ok) return ok.error();
  for (const std::string& m : methods)
    if (const auto k = method_from_key(m);
        k != EffectMethod::LightAtlas && k != EffectMethod::Prm && k != EffectMethod::Antiradiance)
      log.log(m + ": not sharded, baked by the merge (docs/distributed-bake.md)");
  const fs::path dir = shard_directory(bundle_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return engine::Error{dir.string(), "", "cannot create the shard directory: " + ec.message()};
  const fs::path path = dir / shard_file_name(index, count);
  if (auto ok = write_shard_file(path, file); !ok) return ok.error();
  std::error_code size_ec;
  const auto bytes = fs::file_size(path, size_ec);
  for (BakedMethod& m : report.baked) m.bytes = size_ec ? 0 : static_cast<std::uint64_t>(bytes);
  log.log("wrote " + path.string());
  return report;
}

engine::Result<MergedParts> read_shards(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                        const std::vector<std::string>& methods, const BakeHost& host) {
  const fs::path dir = shard_directory(bundle_dir);
  auto files = list_shard_files(dir, ".gishard");
  if (!files) return files.error();
  const ShardFile expected = shard_header(input, options, methods, 0, options.shard_count);
  std::uint32_t count = options.shard_count;
  ShardSet<ShardFile> set;
  for (const fs::path& path : *files) {
    auto file = read_shard_file(path);
    if (!file) return file.error();
    if (count == 0) count = file->count;
    if (auto ok = check_shard(path, *file, expected, count, methods); !ok) return ok.error();
    const std::uint32_t index = file->index;
    if (auto ok = set.place(path, index, count, std::move(file).value()); !ok) return ok.error();
  }
  if (auto ok = set.complete(count, [&](std::uint32_t i) { return dir / shard_file_name(i, count); }); !ok)
    return ok.error();
  auto& shards = set.shards;
  const auto& where = set.where;
  MergedParts merged;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (shards[i]->atlas) merged.atlas.push_back(std::move(*shards[i]->atlas));
    if (shards[i]->prm) merged.prm.push_back(std::move(*shards[i]->prm));
    if (shards[i]->antiradiance) {
      auto links = unpack_link_shard(where[i], shards[i]->antiradiance->frame, shards[i]->antiradiance->links);
      if (!links) return links.error();
      merged.antiradiance.push_back(std::move(links).value());
    }
  }
  if (host.log) host.log(LogLevel::Info, format_line("merging %u shards from %s", count, dir.string().c_str()));
  return merged;
}

}  // namespace gi
