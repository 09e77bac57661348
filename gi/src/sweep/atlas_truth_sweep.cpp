#include "sweep/atlas_truth_sweep.h"

#include <engine/scene.h>
#include <gi/reference.h>

#include <chrono>
#include <string>

#include "core/stopwatch.h"
#include "sweep/atlas_split_truth.h"
#include "sweep/reference_sweep.h"

namespace gi {
namespace {

// The two estimates of a split truth draw from streams of their own, apart from the runs'
// (seed 1 by default) and from the one-estimate references of reference_sweep.cpp.
constexpr std::uint64_t kSplitTruthSeeds[2] = {0x73706c6974310001ULL, 0x73706c6974320002ULL};

TexelPlacement placement_of(const std::string& text) {
  return text == "raster" ? TexelPlacement::Raster : TexelPlacement::VisibleSurface;
}

// The path tracer's atlas of the scene's static world (what the light atlas bakes).
engine::Result<AtlasReference> trace_atlas(const SweepScene& s, double texels_per_m, TexelPlacement placement,
                                           const ReferenceSettings& settings) {
  return reference_atlas(static_world(bake_input_from(engine::instantiate(s.asset))), static_cast<float>(texels_per_m),
                         settings, placement);
}

RgbField indirect_field(const AtlasReference& a) {
  return RgbField::from_texels(a.width, a.height, a.indirect, a.valid, a.indirect_variance);
}
RgbField total_field(const AtlasReference& a) { return RgbField::from_texels(a.width, a.height, a.total, a.valid); }

engine::Result<RgbField> compute_split_truth(const ReferenceJob& job) {
  const ReferenceRequest& r = job.request;
  if (r.param("estimates") != "2") return engine::Error{"<sweep>", r.key(), "a split truth is the mean of estimates=2"};
  AtlasReference halves[2];
  for (int e = 0; e < 2; ++e) {
    ReferenceSettings settings;
    settings.samples_per_pixel = std::stoi(r.param("spp"));
    settings.seed = kSplitTruthSeeds[e];
    settings.threads = job.threads;
    settings.progress = [&job, e](double f) { return !job.progress || job.progress(0.5 * (e + f)); };
    auto truth = trace_atlas(job.scene, std::stod(r.param("texels_per_m")), placement_of(r.param("texels")), settings);
    if (!truth) return truth.error();
    halves[e] = std::move(truth.value());
  }
  // The indirect half's noise from the tracer's own variances, the total's from the two
  // estimates' difference (the tracer gives none for the direct light).
  RgbField indirect = mean_of_two_estimates(indirect_field(halves[0]), indirect_field(halves[1]));
  RgbField total = mean_of_two_estimates(total_field(halves[0]), total_field(halves[1]));
  indirect.valid = halves[0].valid;
  total.valid = halves[0].valid;
  return stack_split_truth(indirect, total);
}

std::vector<KnobSpec> pathtracer_atlas_knobs() {
  return {
      {.name = "spp",
       .description = "samples per texel",
       .kind = KnobKind::Integer,
       .default_grid = {"16", "64", "256"},
       .min_value = 1,
       .max_value = 1 << 20},
      {.name = "density",
       .description = "atlas texels per metre",
       .kind = KnobKind::Real,
       .default_grid = {"32"},
       .min_value = 0.01,
       .max_value = 1e4},
      {.name = "texels",
       .description = "sample points: visible_surface (the final gather's) or raster (VPL shooting's)",
       .kind = KnobKind::Choice,
       .default_grid = {"visible_surface"},
       .choices = {"visible_surface", "raster"}},
      {.name = "ref_spp",
       .description = "samples per texel of the path-traced reference (without --split-truth)",
       .kind = KnobKind::Integer,
       .default_grid = {"4096"},
       .min_value = 1,
       .max_value = 1 << 20},
  };
}

engine::Result<MethodOutput> run_pathtracer_atlas(const RunContext& ctx) {
  ReferenceSettings settings;
  settings.samples_per_pixel = static_cast<int>(ctx.knobs.integer("spp"));
  settings.seed = ctx.seed;
  settings.threads = ctx.threads;
  settings.progress = ctx.progress;
  const auto start = std::chrono::steady_clock::now();
  auto atlas = trace_atlas(ctx.scene, ctx.knobs.real("density"), placement_of(ctx.knobs.text("texels")), settings);
  if (!atlas) return atlas.error();
  MethodOutput out;
  out.costs.bake_seconds = seconds_since(start);
  out.field = RgbField::from_texels(atlas->width, atlas->height, atlas->indirect, atlas->valid);
  out.costs.bytes = static_cast<std::uint64_t>(atlas->width) * static_cast<std::uint64_t>(atlas->height) * 8u;
  if (ctx.split_truth != nullptr) {
    const AtlasSplitTruth truth = unstack_split_truth(*ctx.split_truth);
    if (!truth.total.same_layout(out.field))
      return engine::Error{.message = "the path tracer's atlas size differs from the split truth's"};
    out.extras = split_truth_extras(total_field(*atlas), truth);
  }
  return out;
}

}  // namespace

void register_atlas_truth_sweep(SweepRegistry& registry) {
  // pt2-2: rays below a texel's face are dropped (reference_sweep.cpp, pt-3); pt2-3: the
  // lights' too (pt-4).
  registry.add_reference_provider({.kind = "atlas_split_truth", .version = "pt2-3", .compute = compute_split_truth});

  SweepMethod m;
  m.name = "pathtracer_atlas";
  m.description =
      "the reference path tracer baking the light atlas's texels: samples per texel vs the path-traced atlas truth "
      "(its indirect irradiance; with --split-truth also its total)";
  m.knobs = pathtracer_atlas_knobs();
  m.reference_for = [](const SweepScene&, const KnobSetting& k) {
    return ReferenceRequest::atlas_indirect_irradiance(k.real("density"), static_cast<int>(k.integer("ref_spp")),
                                                       placement_of(k.text("texels")));
  };
  m.split_truth_for = [](const SweepScene&, const KnobSetting& k, int spp) {
    return ReferenceRequest::atlas_split_truth(k.real("density"), spp, placement_of(k.text("texels")));
  };
  m.run = run_pathtracer_atlas;
  registry.add_method(std::move(m));
}

}  // namespace gi
