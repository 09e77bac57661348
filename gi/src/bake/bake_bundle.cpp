// gi::bake_bundle: plan, bake each method into a staged copy of the bundle, swap it in
// (gi/bake.h). The options' mapping onto each method's settings is bake_options.h, the
// staged directory io/staged_directory.h, bake_stats.json bake_stats.h, distributed bakes
// bake_sharding.h.
#include <gi/bake.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include "bake/bake_options.h"
#include "bake/bake_sharding.h"
#include "bake/bake_stage.h"
#include "bake/bake_stats.h"
#include "bake/method_bakers.h"
#include "bundle/geometry_hash.h"
#include "bundle/manifest.h"
#include "core/stopwatch.h"
#include "io/staged_directory.h"
#include "plan/plan_json.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// A method's one key (gi/methods.h): gi-bake --methods, the plan, the manifest.
std::string key_of(EffectMethod m) { return std::string(method_descriptor(m).key); }

// The methods a bake bakes, in order: options.methods, or what the plan calls for and this
// build can bake (the rest in report.skipped); a sky-lit PRM brings the atlas with it.
engine::Result<std::vector<std::string>> methods_to_bake(const BakeInput& input, const BakeOptions& options,
                                                         const BakeHost& host, BakeReport& report) {
  const std::vector<std::string> bakeable = bakeable_methods();
  std::vector<std::string> methods = options.methods;
  if (methods.empty()) {
    for (const PlannedEffect& e : report.plan.effects) {
      if (!e.enabled) continue;
      const std::string key(effect_key(e.method));
      if (std::find(bakeable.begin(), bakeable.end(), key) != bakeable.end() && e.available)
        methods.push_back(key);
      else
        report.skipped.push_back(key);
    }
    for (const std::string& key : report.skipped)
      if (host.log)
        host.log(LogLevel::Warning, "skipping " + key + ": the scene calls for it but this build cannot bake it");
  }
  for (const std::string& key : methods)
    if (std::find(bakeable.begin(), bakeable.end(), key) == bakeable.end())
      return engine::invalid_request("method '" + key + "' is not available in this build (available: " + [&] {
        std::string list;
        for (const std::string& b : bakeable) list += (list.empty() ? "" : ", ") + b;
        return list;
      }() + ")");

  // The sky in a PRM bake (docs/prm.md "The sky"): the sky is a static source, so its light
  // lives in the light atlas the PRM provider composes with (the atlas's final gather
  // resolves it per texel, the PRM's entry points only per cluster and compete for the K
  // active panes). A PRM asked for alone on a sky-lit scene bakes that atlas too, first.
  if (engine::sky_lit(input.environment.sky_radiance, input.environment.sky_gradient) &&
      std::find(methods.begin(), methods.end(), key_of(EffectMethod::Prm)) != methods.end() &&
      std::find(methods.begin(), methods.end(), key_of(EffectMethod::LightAtlas)) == methods.end()) {
    methods.insert(methods.begin(), key_of(EffectMethod::LightAtlas));
    if (host.log)
      host.log(LogLevel::Info, "baking the light atlas too: it carries the sky the PRM composes with (docs/prm.md)");
  }
  return methods;
}

}  // namespace

std::vector<std::string> bakeable_methods() {
  // Every method, in the order a bake runs them (bake/method_bakers.h).
  std::vector<std::string> keys;
  for (const MethodBakerEntry& e : method_bakers()) keys.push_back(key_of(e.method));
  return keys;
}

engine::Result<BakeReport> bake_bundle(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                       const BakeHost& host) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  BakeReport report;
  report.plan = plan(input, {.preset = options.preset,
                             .moving_lights = options.moving_lights,
                             .texels_per_metre = options.texels_per_metre,
                             .vpls = options.vpls,
                             .samples_per_vpl = options.samples_per_vpl,
                             .bounces = options.bounces});
  // The preset is checked before anything is baked or written.
  if (auto density = light_atlas_preset(options.preset); !density) return density.error();

  auto resolved = methods_to_bake(input, options, host, report);
  if (!resolved) return resolved.error();
  const std::vector<std::string> methods = std::move(resolved).value();

  // Distributed bakes (docs/distributed-bake.md): one shard's work into its shard file, or
  // the merge of every shard's, which then bakes through the same staging + swap below.
  if (options.shard_count > 0 && !options.merge_shards)
    return bake_shard(input, bundle_dir, options, host, methods, std::move(report));
  std::optional<MergedParts> merged;
  if (options.merge_shards) {
    auto parts = read_shards(input, bundle_dir, options, methods, host);
    if (!parts) return parts.error();
    merged = std::move(parts).value();
  }

  if (methods.empty()) return report;
  auto staged = StagedDirectory::begin(bundle_dir, "bake of this bundle");
  if (!staged) return staged.error();
  const fs::path& dir = staged->path();
  nlohmann::json method_stats = nlohmann::json::object();
  for (const std::string& key : methods) {
    const auto start = Clock::now();
    Timings timings = nlohmann::json::object();
    const MergedParts* parts = merged ? &*merged : nullptr;
    const EffectMethod m = *method_from_key(key);  // methods_to_bake checked every key
    engine::Status done = method_baker(m).bake(MethodBake{input, dir, options, host, parts, timings, methods});
    if (!done) return done.error();
    report.baked.push_back({key, seconds_since(start), method_bytes(dir, key)});
    method_stats[key] = {{"seconds", report.baked.back().seconds}, {"stages", timings}};
  }
  if (auto ok = update_manifest_plan(dir, scene_geometry_hash(input), scene_file_name(input),
                                     plan_to_json_value(report.plan));
      !ok)
    return ok.error();
  if (auto ok = update_bake_stats(dir, method_stats, options.threads); !ok) return ok.error();
  if (auto ok = staged->commit(); !ok) return ok.error();
  return report;
}

}  // namespace gi
