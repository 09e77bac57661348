#include "sweep/light_atlas_sweep.h"

#include <gi/methods.h>

#include <engine/scene.h>

#include <algorithm>

#include "light_atlas/light_atlas.h"
#include "sweep/atlas_split_truth.h"

namespace gi {

namespace {

// The gather's finer knobs (the denoiser's weights, the reads where rays land, the adaptive
// passes) and the reference's samples: the tail of light_atlas_knobs' table.
// Long because it is one table, one entry per knob with its grid and range, read as a list.
std::vector<KnobSpec> gather_detail_knobs() {
  return {
      {.name = "denoise_sigma",
       .description = "gather: the denoiser's value weight, in standard deviations of the difference",
       .kind = KnobKind::Real,
       .default_grid = {"2"},
       .min_value = 0.01,
       .max_value = 1000},
      {.name = "denoise_ridge",
       .description = "gather: the denoiser's local linear fit, its slopes' ridge (-1: local mean)",
       .kind = KnobKind::Real,
       .default_grid = {"-1"},
       .min_value = -1,
       .max_value = 1e6},
      {.name = "source_ridge",
       .description = "gather: the source filter's local linear fit, its slopes' ridge (-1: Gaussian mean)",
       .kind = KnobKind::Real,
       .default_grid = {"-1"},
       .min_value = -1,
       .max_value = 1e6},
      {.name = "outlier",
       .description =
           "gather: the denoiser's outlier clamp, standard deviations above the co-planar neighbours' mean (0: off)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1000},
      {.name = "landing_direct",
       .description = "gather: the lights' direct light where a fresh ray lands, at the point across shadow edges "
                      "only (edges), everywhere, or everywhere for the punctual lights and the sun only (punctual)",
       .kind = KnobKind::Choice,
       .default_grid = {"edges"},
       .choices = {"edges", "everywhere", "punctual"}},
      {.name = "source_filter",
       .description = "gather: world-space filter radius of the light the fresh rays read, texels (-1: filter's)",
       .kind = KnobKind::Real,
       .default_grid = {"-1"},
       .min_value = -1,
       .max_value = 16},
      {.name = "near_rays",
       .description = "gather: landings nearer than near_texels regather the sky and indirect light at the point "
                      "with this many rays (0: read from the texels)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 4096},
      {.name = "near_texels",
       .description = "gather: the distance, in texels, under which a landing regathers (near_rays)",
       .kind = KnobKind::Real,
       .default_grid = {"1"},
       .min_value = 0,
       .max_value = 64},
      {.name = "near_depth",
       .description = "gather: the levels of regathers at near landings (1: the regather's rays read the texels)",
       .kind = KnobKind::Integer,
       .default_grid = {"1"},
       .min_value = 1,
       .max_value = 8},
      {.name = "near_deep_rays",
       .description = "gather: rays of each regather below the first level (0: near_rays)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 4096},
      {.name = "adaptive",
       .description = "gather: the share of the texels, those whose kept rays read the most variable light, that "
                      "gather adaptive_passes more times (0: none)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1},
      {.name = "adaptive_passes",
       .description = "gather: the extra gathers of the texels `adaptive` chooses",
       .kind = KnobKind::Integer,
       .default_grid = {"1"},
       .min_value = 1,
       .max_value = 16},
      {.name = "ref_spp",
       .description = "samples per texel of the path-traced reference",
       .kind = KnobKind::Integer,
       .default_grid = {"4096"},
       .min_value = 1,
       .max_value = 1 << 20},
  };
}

// Long because it is one table, one entry per knob with its grid and range, read as a list.
std::vector<KnobSpec> light_atlas_knobs() {
  std::vector<KnobSpec> knobs = {
      {.name = "vpls",
       .description = "target VPL count",
       .kind = KnobKind::Integer,
       .default_grid = {"100", "300", "1000", "3000"},
       .min_value = 1,
       .max_value = 1'000'000},
      {.name = "bounces",
       .description = "indirect bounces carried by the atlas",
       .kind = KnobKind::Integer,
       .default_grid = {"1", "2", "3", "5", "8"},
       .min_value = 1,
       .max_value = 64},
      {.name = "density",
       .description = "atlas texels per metre",
       .kind = KnobKind::Real,
       .default_grid = {"32"},
       .min_value = 0.01,
       .max_value = 1e4},
      {.name = "samples",
       .description = "sample points per VPL",
       .kind = KnobKind::Integer,
       .default_grid = {"10"},
       .min_value = 1,
       .max_value = 1024},
      {.name = "final",
       .description = "step 4: shoot (the paper's VPL final shooting) or gather (texel final gather)",
       .kind = KnobKind::Choice,
       .default_grid = {"shoot"},
       .choices = {"shoot", "gather"}},
      {.name = "rays",
       .description = "gather: fresh final-gather rays per texel (0: the kept-ray solve alone)",
       .kind = KnobKind::Integer,
       .default_grid = {"128"},
       .min_value = 0,
       .max_value = 1 << 20},
      {.name = "emitter_rays",
       .description = "gather: fresh rays per texel aimed at the bright texels, MIS with the cosine rays (0: none)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1 << 20},
      {.name = "solve_rays",
       .description = "gather: kept rays per texel iterated for every bounce",
       .kind = KnobKind::Integer,
       .default_grid = {"64"},
       .min_value = 1,
       .max_value = 65536},
      {.name = "direct_samples",
       .description = "gather: light samples per texel on each area light and on the emitters",
       .kind = KnobKind::Integer,
       .default_grid = {"16"},
       .min_value = 1,
       .max_value = 65536},
      {.name = "filter",
       .description = "gather: world-space filter radius, texels (0: none)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 16},
      {.name = "denoise",
       .description = "gather: guided a-trous denoiser passes (steps 1, 2, 4, ... texels; 0: none)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 8},
  };
  std::vector<KnobSpec> more = gather_detail_knobs();
  knobs.insert(knobs.end(), more.begin(), more.end());
  return knobs;
}

TexelPlacement placement_of(const KnobSetting& k) {
  return k.text("final") == "gather" ? TexelPlacement::VisibleSurface : TexelPlacement::Raster;
}

ReferenceRequest light_atlas_reference_request(const SweepScene&, const KnobSetting& k) {
  return ReferenceRequest::atlas_indirect_irradiance(k.real("density"), static_cast<int>(k.integer("ref_spp")),
                                                     placement_of(k));
}

// The whole lightmap (what gi-bake --include-direct bakes: the atlas plus the static lights'
// direct light) against the split truth, into the run's extras. The VPL final shooting keeps
// no direct light: its extras stay empty.
void add_split_truth_extras(const LightAtlasBake& bake, const RgbField& split_truth, MethodOutput& out) {
  if (bake.live_direct.size() != bake.irradiance.size()) return;
  std::vector<glm::vec3> whole = bake.irradiance;
  if (!bake.settings.include_direct)
    for (std::size_t t = 0; t < whole.size(); ++t) whole[t] += bake.live_direct[t];
  out.extras = split_truth_extras(RgbField::from_texels(bake.width, bake.height, whole, bake.valid),
                                  unstack_split_truth(split_truth));
}

engine::Result<MethodOutput> run_light_atlas(const RunContext& ctx) {
  LightAtlasSettings s;
  s.vpl_count = static_cast<int>(ctx.knobs.integer("vpls"));
  s.bounces = static_cast<int>(ctx.knobs.integer("bounces"));
  s.texels_per_metre = static_cast<float>(ctx.knobs.real("density"));
  s.samples_per_vpl = static_cast<int>(ctx.knobs.integer("samples"));
  if (ctx.knobs.text("final") == "gather") {
    s.final_pass = LightAtlasSettings::FinalPass::TexelGather;
    s.gather.gather_rays = static_cast<int>(ctx.knobs.integer("rays"));
    s.gather.solve_rays = static_cast<int>(ctx.knobs.integer("solve_rays"));
    s.gather.emitter_rays = static_cast<int>(ctx.knobs.integer("emitter_rays"));
    s.gather.direct_samples = static_cast<int>(ctx.knobs.integer("direct_samples"));
    s.gather.filter_radius_texels = static_cast<float>(ctx.knobs.real("filter"));
    s.gather.denoise_passes = static_cast<int>(ctx.knobs.integer("denoise"));
    s.gather.denoise_sigma = static_cast<float>(ctx.knobs.real("denoise_sigma"));
    s.gather.denoise_outlier_sigmas = static_cast<float>(ctx.knobs.real("outlier"));
    s.gather.denoise_slope_ridge = static_cast<float>(ctx.knobs.real("denoise_ridge"));
    s.gather.source_filter_slope_ridge = static_cast<float>(ctx.knobs.real("source_ridge"));
    const std::string landing = ctx.knobs.text("landing_direct");
    s.gather.landing_direct = landing == "everywhere" ? gi::TexelGatherSettings::LandingDirect::Everywhere
                              : landing == "punctual" ? gi::TexelGatherSettings::LandingDirect::Punctual
                                                      : gi::TexelGatherSettings::LandingDirect::Edges;
    s.gather.source_filter_radius_texels = static_cast<float>(ctx.knobs.real("source_filter"));
    s.gather.near_regather_rays = static_cast<int>(ctx.knobs.integer("near_rays"));
    s.gather.near_regather_texels = static_cast<float>(ctx.knobs.real("near_texels"));
    s.gather.near_regather_depth = static_cast<int>(ctx.knobs.integer("near_depth"));
    s.gather.near_regather_deep_rays = static_cast<int>(ctx.knobs.integer("near_deep_rays"));
    s.gather.adaptive_share = static_cast<float>(ctx.knobs.real("adaptive"));
    s.gather.adaptive_passes = static_cast<int>(ctx.knobs.integer("adaptive_passes"));
    s.gather.bounces = std::max(s.bounces, 1);
  }
  s.seed = ctx.seed;
  s.threads = ctx.threads;
  s.progress = ctx.progress;
  const engine::Scene scene = engine::instantiate(ctx.scene.asset);
  auto bake = bake_light_atlas(bake_input_from(scene), s);
  if (!bake) return bake.error();
  if (bake->width != ctx.reference.width || bake->height != ctx.reference.height)
    return engine::Error{.message = "the bake's atlas size differs from the reference's"};
  MethodOutput out;
  out.field = RgbField::from_texels(bake->width, bake->height, bake->irradiance, bake->valid);
  out.costs.bake_seconds = bake->stats.total_seconds;
  // What a game ships: the atlas as RGBA16F.
  out.costs.bytes = static_cast<std::uint64_t>(bake->width) * static_cast<std::uint64_t>(bake->height) * 8u;
  if (ctx.split_truth != nullptr) add_split_truth_extras(*bake, *ctx.split_truth, out);
  return out;
}

}  // namespace

void register_light_atlas_sweep(SweepRegistry& registry) {
  SweepMethod m;
  m.name = method_descriptor(EffectMethod::LightAtlas).key;  // gi/methods.h
  m.description =
      "light atlas (Schärfig 2016): VPL final shooting or texel final gather, VPLs x bounces x rays x texel density vs "
      "path-traced indirect irradiance";
  m.knobs = light_atlas_knobs();
  m.reference_for = light_atlas_reference_request;
  m.split_truth_for = [](const SweepScene&, const KnobSetting& k, int spp) {
    return ReferenceRequest::atlas_split_truth(k.real("density"), spp, placement_of(k));
  };
  m.run = run_light_atlas;
  registry.add_method(std::move(m));
}

}  // namespace gi
