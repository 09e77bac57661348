#include "light_atlas/light_atlas.h"

#include <engine/sky.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <span>

#include "core/color.h"
#include "core/random.h"
#include "core/stopwatch.h"
#include "light_atlas/final_shooting.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"
#include "transport/vpl_transport.h"
#include "uv/atlas_density.h"
#include "uv/atlas_dilation.h"
#include "uv/atlas_input.h"

namespace gi {
namespace {

using Clock = std::chrono::steady_clock;

engine::Status validate(const LightAtlasSettings& s) {
  const auto bad = [](std::string what) { return engine::invalid_request("light-atlas settings: " + what); };
  if (!(s.texels_per_metre > 0.0f) || s.texels_per_metre > kMaxTexelsPerMetre)
    return bad("texels_per_metre " + std::to_string(s.texels_per_metre) + " is outside (0, 10^4]");
  if (s.vpl_count < 1 || s.vpl_count > 1'000'000)
    return bad("vpl_count " + std::to_string(s.vpl_count) + " is outside 1..10^6");
  if (s.samples_per_vpl < 1 || s.samples_per_vpl > 1024)
    return bad("samples_per_vpl " + std::to_string(s.samples_per_vpl) + " is outside 1..1024");
  if (s.bounces < 1 || s.bounces > 64) return bad("bounces " + std::to_string(s.bounces) + " is outside 1..64");
  if (!(s.unshot_threshold >= 0.0f) || !std::isfinite(s.unshot_threshold))
    return bad("unshot_threshold must be finite and >= 0");
  if (s.area_light_samples < 1 || s.area_light_samples > 65536)
    return bad("area_light_samples " + std::to_string(s.area_light_samples) + " is outside 1..65536");
  return {};
}

// The static scene (bake/static_scene.h) with the static lights, and their point emitters.
struct BakeScene : StaticBakeScene {
  std::vector<PointEmitter> emitters;
};

engine::Result<BakeScene> prepare(const BakeInput& input, const AtlasLayout& layout, const LightAtlasSettings& s) {
  // Lights that move belong to PRM (DESIGN.md 3): the atlas bakes the static ones only.
  auto prepared = prepare_static_scene(input, layout, BakeLights::Static, texel_placement(s));
  if (!prepared) return prepared.error();
  BakeScene b{std::move(prepared).value(), {}};
  b.emitters = point_emitters(b.scene, b.index, s.area_light_samples, s.seed);
  return b;
}

// Phases' shares of the progress bar (roughly their share of the time on our scenes).
struct Phase {
  double begin, end;
};
constexpr Phase kDirectPhase{0.02, 0.10}, kPropagatePhase{0.10, 0.35}, kFinalPhase{0.35, 1.0};

ProgressCallback sub_progress(const ProgressCallback& p, Phase ph) {
  if (!p) return {};
  return [p, ph](double f) { return p(ph.begin + (ph.end - ph.begin) * f); };
}

struct VplPowers {
  std::vector<glm::vec3> power;
  std::size_t shots = 0;
  std::uint64_t rays = 0;
};

// The sky's direct light on every VPL, area-weighted over its sample points: cosine-sampled
// rays (stratified, one random stream per VPL) that escape the static world bring the sky's radiance,
// E = pi / M x sum of L(w) over escaping rays. With it the VPL solution — the VPL-shooting
// atlas's bounces and the world probes built from the VPLs at load, which light dynamic
// objects — carries the sky's bounce off the static world, as the gather does per texel.
void add_sky_to_vpls(const BakeScene& b, const VplSet& vpls, std::uint64_t seed, ThreadPool& pool,
                     std::vector<glm::vec3>& direct, std::uint64_t* rays) {
  const glm::vec3 uniform = b.scene.sky_radiance;
  const engine::SkyGradient& gradient = b.scene.sky_gradient;
  if (!engine::sky_lit(uniform, gradient)) return;
  constexpr std::uint32_t kRaysPerSample = 16;
  constexpr std::uint64_t kSkyStream = 0x736b79u;  // "sky"
  std::atomic<std::uint64_t> traced{0};
  pool.parallel_for(
      vpls.size(),
      [&](std::size_t j) {
        Pcg32 rng = Pcg32::for_item(seed ^ kSkyStream, j);
        glm::dvec3 sum(0.0);
        std::uint64_t local = 0;
        for (std::uint32_t k = vpls.sample_first[j]; k < vpls.sample_first[j + 1]; ++k) {
          const glm::vec3& n = vpls.sample_normal[k];
          const glm::vec3 origin = offset_ray_origin(vpls.sample_position[k], n);
          glm::vec3 seen(0.0f);
          for (std::uint32_t r = 0; r < kRaysPerSample; ++r) {  // stratified in the first dimension
            const float u1 = std::min((static_cast<float>(r) + rng.next_float()) / kRaysPerSample, 0x1.fffffep-1f);
            const glm::vec3 wi = sample_cosine_hemisphere(n, u1, rng.next_float());
            ++local;
            if (!b.caster->occluded(Ray{origin, 0.0f, wi})) seen += engine::sky_radiance(uniform, gradient, wi);
          }
          sum += glm::dvec3(seen) * (3.14159265358979 / kRaysPerSample) * static_cast<double>(vpls.sample_area_m2[k]);
        }
        direct[j] += glm::vec3(sum / static_cast<double>(vpls.area_m2[j]));
        traced += local;
      },
      16);
  if (rays) *rays += traced.load();
}

// Steps 2-3: direct light into the VPLs, then progressive refinement; returns every VPL's
// reflected power E_i = rho_i A_i I_i.
engine::Result<VplPowers> light_vpls(const BakeScene& b, const VplSet& vpls, const LightAtlasSettings& s,
                                     ThreadPool& pool, LightAtlasStats* stats) {
  VplPowers out;
  auto t0 = Clock::now();
  std::vector<glm::vec3> direct = direct_to_vpls(vpls, b.emitters, *b.caster, pool, &out.rays);
  add_sky_to_vpls(b, vpls, s.seed, pool, direct, &out.rays);
  if (stats) stats->direct_seconds = seconds_since(t0);
  if (s.progress && !s.progress(kDirectPhase.end)) return engine::cancelled_error("light-atlas bake");
  t0 = Clock::now();
  auto solution = propagate(vpls, direct, *b.caster, pool,
                            {.bounces = s.bounces,
                             .unshot_threshold = s.unshot_threshold,
                             .seed = s.seed,
                             .progress = sub_progress(s.progress, kPropagatePhase)});
  if (!solution) return solution.error();
  if (stats) stats->propagate_seconds = seconds_since(t0);
  out.shots = solution->shots;
  out.rays += solution->rays;
  out.power.resize(vpls.size());
  for (std::size_t i = 0; i < vpls.size(); ++i)
    out.power[i] = vpls.albedo[i] * vpls.area_m2[i] * solution->irradiance[i];
  return out;
}

// Sky rays per texel of the VPL final shooting's baked direct light (the gather presets
// count the sky on their own solve and gather rays instead).
constexpr int kVplSkyRays = 64;

}  // namespace

namespace {

// How bake_light_atlas runs: whole, as one shard (steps 1-3 of texel_gather.h, step 3 for
// the shard's texels, nothing after), or as the merge of the shards' parts.
struct ShardRun {
  WorkShard shard;  // with part: whose texel blocks
  LightAtlasShardPart* part = nullptr;
  const std::vector<LightAtlasShardPart>* parts = nullptr;  // set: the merge
};

// The gather's valid texels in index order (what WorkShard items index), as texel_gather.cpp.
std::vector<std::uint32_t> gather_work(const AtlasTexels& texels) {
  std::vector<std::uint32_t> work;
  for (std::size_t i = 0; i < texels.valid.size(); ++i)
    if (texels.valid[i]) work.push_back(static_cast<std::uint32_t>(i));
  return work;
}

// The merge: the gather result of a whole bake before its filter, assembled from the parts.
engine::Result<TexelGatherResult> assemble_parts(const AtlasTexels& texels,
                                                 const std::vector<LightAtlasShardPart>& parts) {
  const std::vector<std::uint32_t> work = gather_work(texels);
  const std::size_t n = texels.valid.size();
  TexelGatherResult out;
  out.indirect.assign(n, glm::vec3(0.0f));
  out.direct.assign(n, glm::vec3(0.0f));
  out.baked_direct.assign(n, glm::vec3(0.0f));
  out.hidden.assign(n, 0);
  out.variance.assign(n, 0.0f);
  const auto count = static_cast<std::uint32_t>(parts.size());
  for (std::uint32_t i = 0; i < count; ++i) {
    const LightAtlasShardPart& p = parts[i];
    const WorkShard shard{.index = i, .count = count};
    std::vector<std::uint32_t> expected;
    for (std::size_t w = 0; w < work.size(); ++w)
      if (shard.owns(w)) expected.push_back(work[w]);
    if (p.texels != expected || p.indirect.size() != expected.size() || p.direct.size() != expected.size() ||
        p.baked_direct.size() != expected.size() || p.hidden.size() != expected.size() ||
        p.variance.size() != expected.size())
      return engine::Error{.message = "light-atlas shard " + std::to_string(i) + " of " + std::to_string(count) +
                                      ": its texels are not that shard's texels of this scene's atlas"};
    for (std::size_t k = 0; k < expected.size(); ++k) {
      out.indirect[expected[k]] = p.indirect[k];
      out.direct[expected[k]] = p.direct[k];
      out.baked_direct[expected[k]] = p.baked_direct[k];
      out.hidden[expected[k]] = p.hidden[k];
      out.variance[expected[k]] = p.variance[k];
    }
    out.own_rays += p.own_rays;
  }
  out.shared_rays = parts.empty() ? 0 : parts.front().shared_rays;
  out.rays = out.shared_rays + out.own_rays;
  return out;
}

engine::Result<LightAtlasBake> bake_light_atlas_run(const BakeInput& input, const LightAtlasSettings& settings,
                                                    const ShardRun& run);

}  // namespace

engine::Result<LightAtlasShardPart> bake_light_atlas_shard(const BakeInput& input, const LightAtlasSettings& settings,
                                                           WorkShard shard) {
  if (shard.count == 0 || shard.index >= shard.count)
    return engine::invalid_request("light-atlas shard " + std::to_string(shard.index) + " of " +
                                   std::to_string(shard.count) + " does not exist");
  if (settings.final_pass != LightAtlasSettings::FinalPass::TexelGather)
    return engine::invalid_request("the light atlas's VPL final shooting cannot be sharded (the presets gather)");
  LightAtlasShardPart part;
  auto done = bake_light_atlas_run(input, settings, ShardRun{.shard = shard, .part = &part, .parts = nullptr});
  if (!done) return done.error();
  return part;
}

namespace {

// One shard: steps 1-3 of the gather, step 3 for its texel blocks, into *run.part.
engine::Status gather_shard_part(const BakeScene& b, const AtlasLayout& layout, const LightAtlasSettings& settings,
                                 const ShardRun& run, ThreadPool& pool) {
  TexelGatherSettings g = settings.gather;
  g.seed = settings.seed;
  g.progress = settings.progress;
  g.shard = run.shard;
  g.part_only = true;
  auto gathered = gather_atlas(b, layout, g, pool);
  if (!gathered) return gathered.error();
  const std::vector<std::uint32_t> work = gather_work(b.texels);
  LightAtlasShardPart& p = *run.part;
  for (std::size_t w = 0; w < work.size(); ++w) {
    if (!run.shard.owns(w)) continue;
    const std::uint32_t i = work[w];
    p.texels.push_back(i);
    p.indirect.push_back(gathered->indirect[i]);
    p.direct.push_back(gathered->direct[i]);
    p.baked_direct.push_back(gathered->baked_direct[i]);
    p.hidden.push_back(gathered->hidden[i]);
    p.variance.push_back(gathered->variance[i]);
  }
  p.shared_rays = gathered->shared_rays;
  p.own_rays = gathered->own_rays;
  return {};
}

// The VPLs (what BRF's world probes read) take their light from the gathered atlas: the
// area-weighted mean of the total irradiance at their sample points' texels, instead of
// a VPL solution of their own (steps 2-3 cost more than the gather at 1000+ VPLs).
void vpl_power_from_atlas(const BakeScene& b, const TexelGatherResult& gathered, LightAtlasBake& out) {
  std::vector<glm::vec3> total(out.irradiance.size());
  for (std::size_t t = 0; t < total.size(); ++t)
    total[t] = out.irradiance[t] + gathered.direct[t] + gathered.baked_direct[t];
  const std::vector<glm::vec3> at_samples = irradiance_at_points(b.texels, total, out.layout.texels_per_metre,
                                                                 out.vpls.sample_position, out.vpls.sample_normal);
  out.vpl_power.assign(out.vpls.size(), glm::vec3(0.0f));
  for (std::size_t j = 0; j < out.vpls.size(); ++j) {
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::uint32_t k = out.vpls.sample_first[j]; k < out.vpls.sample_first[j + 1]; ++k) {
      sum += glm::dvec3(at_samples[k]) * static_cast<double>(out.vpls.sample_area_m2[k]);
      area += static_cast<double>(out.vpls.sample_area_m2[k]);
    }
    if (area > 0.0) out.vpl_power[j] = out.vpls.albedo[j] * out.vpls.area_m2[j] * glm::vec3(sum / area);
  }
}

// The texel final gather (texel_gather.h), or the merge of the shards' gathers, into
// out.irradiance and out.vpl_power; adds its rays to `rays`.
engine::Status texel_gather_pass(const BakeScene& b, const LightAtlasSettings& settings, const ShardRun& run,
                                 ThreadPool& pool, LightAtlasBake& out, std::uint64_t& rays) {
  const auto t0 = Clock::now();
  TexelGatherSettings g = settings.gather;
  g.seed = settings.seed;
  g.progress = sub_progress(settings.progress, Phase{kDirectPhase.begin, kFinalPhase.end});
  auto gathered = run.parts ? assemble_parts(b.texels, *run.parts) : gather_atlas(b, out.layout, g, pool);
  if (!gathered) return gathered.error();
  if (run.parts) {  // the merge: the whole bake's last gather step on the shards' texels
    if (auto ok = filter_gathered(b, out.layout, g, pool, *gathered); !ok) return ok.error();
    if (g.progress && !g.progress(1.0)) return engine::cancelled_error("light-atlas merge");
  }
  out.stats.direct_seconds = gathered->direct_seconds;
  out.irradiance = std::move(gathered->indirect);
  rays += gathered->rays;
  out.stats.gather_iterations = gathered->iterations;
  vpl_power_from_atlas(b, *gathered, out);
  // The atlas holds what the renderer does not draw (the sky, unlit emitters), and with
  // include_direct the static lights' direct light too.
  for (std::size_t t = 0; t < out.irradiance.size(); ++t) {
    out.irradiance[t] += gathered->baked_direct[t];
    if (settings.include_direct) out.irradiance[t] += gathered->direct[t];
  }
  out.live_direct = std::move(gathered->direct);
  out.stats.final_seconds = seconds_since(t0) - gathered->direct_seconds;
  return {};
}

// The VPL final shooting: the VPLs lit, then shot into the atlas, with the direct light the
// renderer does not draw; into out.irradiance and out.vpl_power; adds its rays to `rays`.
engine::Status vpl_shooting_pass(const BakeScene& b, const LightAtlasSettings& settings, ThreadPool& pool,
                                 LightAtlasBake& out, std::uint64_t& rays) {
  auto powers = light_vpls(b, out.vpls, settings, pool, &out.stats);
  if (!powers) return powers.error();
  out.vpl_power = powers->power;
  out.stats.shots = powers->shots;
  rays += powers->rays;
  const auto t0 = Clock::now();
  std::vector<std::uint32_t> shooters;
  std::vector<glm::vec3> shot;
  for (std::uint32_t i = 0; i < out.vpls.size(); ++i)
    if (out.vpl_power[i] != glm::vec3(0.0f)) shooters.push_back(i), shot.push_back(out.vpl_power[i]);
  // Texels are point samples of irradiance (as the reference's): no receiver area; the
  // emitter's sample areas alone bound the near field.
  auto final_result =
      shoot_into_atlas(out.vpls, shooters, shot, b.texels, 0.0f, *b.caster, pool,
                       {.seed = settings.seed, .progress = sub_progress(settings.progress, kFinalPhase)});
  if (!final_result) return final_result.error();
  out.irradiance = std::move(final_result->irradiance);
  rays += final_result->rays;
  // The direct light the renderer does not draw (the sky's, and that of emitters no light
  // stands for), and with include_direct every emitter's.
  std::vector<PointEmitter> unlit;
  for (const PointEmitter& e : b.emitters)
    if (!e.drawn_live) unlit.push_back(e);
  const float texel_area = 1.0f / (out.layout.texels_per_metre * out.layout.texels_per_metre);
  const std::vector<glm::vec3> direct =
      direct_into_atlas(settings.include_direct ? b.emitters : unlit, b.texels, texel_area, *b.caster, pool, &rays);
  for (std::size_t t = 0; t < direct.size(); ++t) out.irradiance[t] += direct[t];
  if (engine::sky_lit(b.scene.sky_radiance, b.scene.sky_gradient)) {
    auto sky = sky_direct_light(b, out.layout, kVplSkyRays, settings.seed, pool);
    if (!sky) return sky.error();
    for (std::size_t t = 0; t < direct.size(); ++t) out.irradiance[t] += (*sky)[t];
  }
  out.stats.final_seconds = seconds_since(t0);
  return {};
}

engine::Result<LightAtlasBake> bake_light_atlas_run(const BakeInput& input, const LightAtlasSettings& settings,
                                                    const ShardRun& run) {
  if (auto ok = validate(settings); !ok) return ok.error();
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  const auto t_start = Clock::now();
  auto layout = static_world_layout(input, settings.texels_per_metre);
  if (!layout) return layout.error();
  const double layout_seconds = seconds_since(t_start);

  ThreadPool pool(settings.threads);
  auto t0 = Clock::now();
  auto prepared = prepare(input, *layout, settings);
  if (!prepared) return prepared.error();
  const BakeScene& b = *prepared;

  if (run.part) {
    if (auto ok = gather_shard_part(b, *layout, settings, run, pool); !ok) return ok.error();
    return LightAtlasBake{};
  }

  LightAtlasBake out;
  out.stats.layout_seconds = layout_seconds;
  out.stats.prepare_seconds = seconds_since(t0);
  out.settings = settings;
  out.layout = std::move(layout).value();
  out.width = out.layout.width;
  out.height = out.layout.height;
  t0 = Clock::now();
  auto vpls = distribute_vpls(
      b.scene, b.index,
      {.vpl_count = settings.vpl_count, .samples_per_vpl = settings.samples_per_vpl, .seed = settings.seed});
  if (!vpls) return vpls.error();
  out.vpls = std::move(vpls).value();
  out.stats.vpl_seconds = seconds_since(t0);

  std::uint64_t rays = 0;
  const engine::Status finished = settings.final_pass == LightAtlasSettings::FinalPass::TexelGather
                                      ? texel_gather_pass(b, settings, run, pool, out, rays)
                                      : vpl_shooting_pass(b, settings, pool, out, rays);
  if (!finished) return finished.error();
  out.valid = b.texels.valid;
  dilate<glm::vec3>(out.irradiance, out.width, out.height, out.valid, atlas_gutter_rings(out.layout.padding_texels));

  out.stats.vpls = out.vpls.size();
  out.stats.sample_points = out.vpls.sample_position.size();
  out.stats.light_points = b.emitters.size();
  out.stats.valid_texels = static_cast<std::size_t>(std::count(out.valid.begin(), out.valid.end(), std::uint8_t{1}));
  out.stats.rays = rays;
  out.stats.total_seconds = seconds_since(t_start);
  return out;
}

}  // namespace

engine::Result<LightAtlasBake> bake_light_atlas(const BakeInput& input, const LightAtlasSettings& settings) {
  return bake_light_atlas_run(input, settings, {});
}

engine::Result<LightAtlasBake> merge_light_atlas(const BakeInput& input, const LightAtlasSettings& settings,
                                                 const std::vector<LightAtlasShardPart>& parts) {
  if (parts.empty()) return engine::invalid_request("light-atlas merge: no shard");
  if (settings.final_pass != LightAtlasSettings::FinalPass::TexelGather)
    return engine::invalid_request("the light atlas's VPL final shooting cannot be sharded (the presets gather)");
  return bake_light_atlas_run(input, settings, {.shard = {}, .part = nullptr, .parts = &parts});
}

engine::Result<LightAtlasUpdateStats> update_light_atlas(const BakeInput& input, LightAtlasBake& previous,
                                                         float relative_threshold) {
  if (!(relative_threshold >= 0.0f) || !std::isfinite(relative_threshold))
    return engine::Error{.message = "incremental light-atlas update: the threshold must be finite and >= 0"};
  if (previous.settings.include_direct)
    return engine::Error{.message =
                             "incremental light-atlas update needs an indirect-only atlas (include_direct is set)"};
  const auto t_start = Clock::now();
  LightAtlasSettings settings = previous.settings;
  settings.progress = {};
  ThreadPool pool(settings.threads);
  auto prepared = prepare(input, previous.layout, settings);
  if (!prepared) return prepared.error();
  const BakeScene& b = *prepared;
  if (b.texels.valid != previous.valid || previous.vpl_power.size() != previous.vpls.size())
    return engine::Error{.message =
                             "incremental light-atlas update: the scene's geometry differs from the bake's; re-bake"};

  auto powers = light_vpls(b, previous.vpls, settings, pool, nullptr);
  if (!powers) return powers.error();
  float largest = 0.0f;
  for (const glm::vec3& e : powers->power) largest = std::max(largest, max_component(e));
  std::vector<std::uint32_t> shooters;
  std::vector<glm::vec3> delta;
  for (std::uint32_t i = 0; i < previous.vpls.size(); ++i) {
    const glm::vec3 d = powers->power[i] - previous.vpl_power[i];
    const float change = std::max(std::fabs(d.x), std::max(std::fabs(d.y), std::fabs(d.z)));
    if (change > relative_threshold * largest && change > 0.0f) {
      shooters.push_back(i);
      delta.push_back(d);
      previous.vpl_power[i] = powers->power[i];  // what the atlas now holds for VPL i
    }
  }
  auto diff =
      shoot_into_atlas(previous.vpls, shooters, delta, b.texels, 0.0f, *b.caster, pool, {.seed = settings.seed});
  if (!diff) return diff.error();
  for (std::size_t t = 0; t < previous.irradiance.size(); ++t) {
    if (!previous.valid[t]) continue;
    // Differences may undershoot zero by rounding where a light went dark.
    previous.irradiance[t] = glm::max(previous.irradiance[t] + diff->irradiance[t], glm::vec3(0.0f));
  }
  dilate<glm::vec3>(previous.irradiance, previous.width, previous.height, previous.valid,
                    atlas_gutter_rings(previous.layout.padding_texels));
  return LightAtlasUpdateStats{.reshot_vpls = shooters.size(), .seconds = seconds_since(t_start)};
}

// Final gather (texel_gather.h), chosen from the sweeps against the truth (the
// reference's own noise removed, docs/light_atlas.md) on the Cornell box at 128 texels/m
// (docs/sweeps/light_atlas_128) and the demo level at 16 texels/m, and from the demo's
// frames: kept rays alone with the 2.5-texel filter reach the same error for less, but
// leave blotches a few texels wide where few bright texels light a wall (the crate room
// at 16 kept rays); a few fresh gather rays reading the filtered solve remove them. The
// high preset gathers enough not to blur. The VPLs only feed BRF's world probes.
// Preview and medium denoise with the guided a-trous (2 passes, atlas_denoise.h; the
// filter it replaced and why: docs/light_atlas.md, "The presets").
// Since the eighth session: no output filter; the lights' direct light read at every
// landing point, the light the rays read filtered by 1.5 texels apart from the output, and
// 32 emitter-sampled rays towards the bright texels. The emitter rays are what lets the
// filter go: the crate room's blotches were texels whose rays hit or missed the lamp's
// small bright patch on the floor, which the emitter rays find every time. Sponza 11.62% /
// 3.02% -> 7.12% / 1.77%; the Cornell box at 128 texels/m 1.215% -> 1.280% (the filter's
// blur of 1.2 cm there cost less than its noise saved; docs/light_atlas.md, "Emitter rays
// instead of the output filter").
// Since the ninth session: a landing nearer than a texel regathers the sky and the indirect
// light at its point with 4 rays of its own instead of reading the texels, whose samples lie
// up to a texel away in other light (corners, ledges, small charts). Sponza 7.12% / 1.77% ->
// 6.03% / 1.46%; the Cornell box 1.280% -> 1.266% (docs/light_atlas.md, "Near landings
// regather at their point").
// Since the eleventh session: only the punctual lights' and the sun's direct light at every
// landing; an area light's one sample there was noise its texels' samples do not have (the
// Cornell box 1.266% -> 1.155%; Sponza, sun and sky only, unchanged; docs/light_atlas.md,
// "The area lights at landings").
// Since the twelfth session: the denoiser and the source filter fit a local plane instead of
// a local mean (a kernel cut off at a chart's edge read the light of its centre of mass), and
// with that bias gone the denoiser takes 3 passes at value sigma 1.5. Sponza (breakdown, 2 x
// 64 spp) 5.45% / 1.17% -> 4.88% / 1.03%; the Cornell box 1.155% -> 0.962% (docs/light_atlas.md,
// "A plane, not a mean").
engine::Result<LightAtlasSettings> light_atlas_preset(std::string_view name) {
  auto density = atlas_density_preset(name);
  if (!density)
    return engine::invalid_request("unknown light-atlas preset '" + std::string(name) + "' (preview, medium, high)");
  LightAtlasSettings s;
  s.texels_per_metre = *density;
  s.final_pass = LightAtlasSettings::FinalPass::TexelGather;
  s.gather.filter_radius_texels = 0.0f;
  s.gather.denoise_passes = 3, s.gather.denoise_sigma = 1.5f, s.gather.denoise_slope_ridge = 0.0f;
  s.gather.source_filter_slope_ridge = 0.0f;
  s.gather.landing_direct = TexelGatherSettings::LandingDirect::Punctual;
  s.gather.source_filter_radius_texels = 1.5f;
  s.gather.emitter_rays = 32;
  s.gather.near_regather_rays = 4;
  // A regather's near landings regather again with one ray (docs/light_atlas.md, "Regathers in
  // corners"): Sponza's indirect-dominated texels 4.34% -> 4.07%, whole 0.99% -> 0.88%, +4% time.
  s.gather.near_regather_depth = 2, s.gather.near_regather_deep_rays = 1;
  if (name == "preview") {
    s.vpl_count = 300, s.bounces = 8;
    s.gather.solve_rays = 32;
    s.gather.gather_rays = 128;
    s.gather.direct_samples = 4;
  } else if (name == "medium") {
    s.vpl_count = 1000, s.bounces = 16;
    s.gather.solve_rays = 32;
    s.gather.gather_rays = 128;  // demo level 0.03 (VPL shooting's medium: 0.10); 16 + 64 rays mottled
    s.gather.direct_samples = 8;
    // The 15% of the texels whose kept rays read the most variable light gather twice
    // (docs/light_atlas.md, "Regathers in corners"): Sponza 4.07% -> 3.64% for +12% time.
    s.gather.adaptive_share = 0.15f, s.gather.adaptive_passes = 1;
  } else {
    s.vpl_count = 3000, s.bounces = 16;
    s.gather.solve_rays = 128;
    s.gather.gather_rays = 1024;  // Cornell at 128 texels/m: below 0.01 (128 + 512: 0.0105)
    s.gather.direct_samples = 16;
    // At 32 texels/m a filter's bias costs more than its noise saves (against a 65536-spp
    // reference, 0.022 with a 1.5-texel filter, 0.015 without).
    s.gather.filter_radius_texels = 0.0f, s.gather.denoise_passes = 0, s.gather.source_filter_slope_ridge = -1.0f;
    s.gather.landing_direct = TexelGatherSettings::LandingDirect::Edges, s.gather.source_filter_radius_texels = -1.0f;
    s.gather.emitter_rays = 0, s.gather.near_regather_rays = 0;
    s.gather.near_regather_depth = 1, s.gather.near_regather_deep_rays = 0;
  }
  return s;
}

TexelPlacement texel_placement(const LightAtlasSettings& settings) {
  return settings.final_pass == LightAtlasSettings::FinalPass::TexelGather ? TexelPlacement::VisibleSurface
                                                                           : TexelPlacement::Raster;
}

std::vector<std::string> light_atlas_preset_names() { return {"preview", "medium", "high"}; }

}  // namespace gi
