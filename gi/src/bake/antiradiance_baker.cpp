// Antiradiance's baker (bake/method_bakers.h): the region, its links (or the shards'), what a load at the baked pose
// computes, save.
#include <chrono>
#include <string>

#include "antiradiance/antiradiance_io.h"
#include "antiradiance/antiradiance_region.h"
#include "bake/bake_options.h"
#include "bake/bake_sharding.h"
#include "bake/bake_stage.h"
#include "bake/method_bakers.h"
#include "bundle/bundle_reader.h"
#include "core/stopwatch.h"
#include "light_atlas/light_atlas_io.h"
#include "prm/prm_io.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

}  // namespace

// The atlas the runtime composites antiradiance into (GISystem: the light atlas's layout,
// else the PRM's) as the bundle in `dir` holds it; none when it holds neither.
std::optional<AtlasLayout> runtime_atlas_layout(const fs::path& dir, const BakeInput& input) {
  for (const char* method : {kLightAtlasMethod, kPrmMethod}) {
    auto bundle = BundleReader::open(dir, method, input, "re-bake");
    if (!bundle) continue;
    // A PRM with coarse panes writes the atlas it is read at (files.atlas_layout), not its panes' layout.
    const std::string key = bundle->entry().contains(kPrmAtlasLayoutKey) ? kPrmAtlasLayoutKey : "layout";
    JsonFields f = bundle->fields();
    const BakedAtlasLayout baked = read_baked_atlas_layout(f, key);
    if (f.error()) continue;
    auto layout = bundle->atlas_layout(input, baked, "atlas layout", key);
    if (layout) return std::move(layout).value();
  }
  return std::nullopt;
}

engine::Status bake_antiradiance_method(const MethodBake& job) {
  const BakeInput& input = job.input;
  const BakeOptions& o = job.options;
  const BakeStage stage{job.host, std::string(effect_name(EffectMethod::Antiradiance))};
  const MergedParts* parts = job.merged;
  const fs::path& dir = job.dir;
  Timings& timings = job.timings;
  const AntiradianceSettings s = antiradiance_settings(o);
  const auto start = Clock::now();
  // A merge (docs/distributed-bake.md): the links from the shards, the rest baked here.
  auto bake = parts != nullptr && !parts->antiradiance.empty()
                  ? bake_antiradiance_from_link_shards(input, s, parts->antiradiance)
                  : bake_antiradiance(input, s);
  if (!bake) return bake.error();
  stage.log(format_line("antiradiance of %s, preset %s: %zu elements (%zu leaves), %d bins, %zu static links, %.2f s",
                        scene_file_name(input).c_str(), o.preset.c_str(), bake->hierarchy.nodes.size(),
                        bake->hierarchy.leaf_count(), s.bins_per_side * s.bins_per_side,
                        bake->static_links.links.size(), seconds_since(start)));
  const AntiradianceSolveReport& rep = bake->baseline_report;
  stage.log(format_line("antiradiance baseline: %d iterations, residual %.2e (tolerance %.0e)%s", rep.iterations,
                        rep.residual, s.residual_tolerance, rep.fell_back ? ", asymmetric fallback" : ""));
  if (rep.budget_exhausted && job.host.log)
    job.host.log(LogLevel::Warning, format_line("antiradiance baseline did not converge in %d iterations (residual "
                                                "%.2e): the runtime's change carries that error",
                                                rep.iterations, rep.residual));
  // links_seconds: linking (a merge: putting the shards' links in place).
  timings["links_seconds"] = bake->seconds.links;
  timings["static_links_seconds"] = bake->seconds.static_links;
  timings["direct_seconds"] = bake->seconds.direct;
  timings["solve_seconds"] = bake->seconds.solve;
  // What a load at the baked pose computes (the posed links, the texel blends of the atlas
  // baked before it in this bundle), stored so the load reads it.
  const auto at_pose_start = Clock::now();
  const std::optional<AtlasLayout> layout = runtime_atlas_layout(dir, input);
  prepare_antiradiance_load(*bake, input, layout ? &*layout : nullptr);
  timings["at_pose_seconds"] = seconds_since(at_pose_start);
  const auto save_start = Clock::now();
  auto saved = save_antiradiance(dir, *bake, input);
  timings["save_seconds"] = seconds_since(save_start);
  return saved;
}

}  // namespace gi
