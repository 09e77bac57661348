#include "sweep/reflection_probes_sweep.h"

#include <gi/error_metrics.h>
#include <gi/methods.h>

#include <engine/gltf_brdf.h>
#include <engine/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "light_atlas/light_atlas.h"
#include "reflection_probes/reflection_probes.h"
#include "sweep/glossy_texels.h"

namespace gi {
namespace {

// The shader's PROBE_BOX_MARGIN_M (engine/shaders/reflection_probes.glsl).
constexpr float kBoxMarginM = 0.05f;

// Long because it is one table, one entry per knob with its grid and range, read as a list.
std::vector<KnobSpec> reflection_probes_knobs() {
  return {
      {.name = "resolution",
       .description = "cube face size of level 0, texels",
       .kind = KnobKind::Integer,
       .default_grid = {"16", "32", "64"},
       .min_value = 4,
       .max_value = 512},
      {.name = "supersample",
       .description = "capture rays per texel side",
       .kind = KnobKind::Integer,
       .default_grid = {"2"},
       .min_value = 1,
       .max_value = 8},
      {.name = "prefilter",
       .description = "GGX samples per prefiltered texel",
       .kind = KnobKind::Integer,
       .default_grid = {"128"},
       .min_value = 1,
       .max_value = 65536},
      {.name = "parallax",
       .description = "parallax correction: the captured distances (distance-impostor search) or the box alone",
       .kind = KnobKind::Choice,
       .default_grid = {"distance"},
       .choices = {"distance", "box"}},
      {.name = "lobe",
       .description = "the lookup's lobe: the split sum's (one read along the reflection, isotropic, n = v) or "
                      "filtered importance sampling of the lobe at the view (probe_lobe_radiance)",
       .kind = KnobKind::Choice,
       .default_grid = {"fis"},
       .choices = {"split_sum", "fis"}},
      {.name = "lobe_samples",
       .description = "GGX samples per probe of the filtered-importance-sampled lookup (lobe=fis)",
       .kind = KnobKind::Integer,
       .default_grid = {"4"},
       .min_value = 1,
       .max_value = kProbeMaxLobeSamples},
      {.name = "atlas",
       .description = "light-atlas preset whose irradiance the captures read on the static surfaces",
       .kind = KnobKind::Choice,
       .default_grid = {"preview"},
       .choices = {"preview", "medium", "high"}},
      {.name = "roughness",
       .description = "roughness of the glossy materials (those below 0.35 in the scene: the floors)",
       .kind = KnobKind::Real,
       .default_grid = {"0.1", "0.2"},
       .min_value = 0.0,
       .max_value = 0.9},
      {.name = "density",
       .description = "texels per metre of the layout the error is measured on",
       .kind = KnobKind::Real,
       .default_grid = {"8"},
       .min_value = 0.01,
       .max_value = 1e4},
      {.name = "border",
       .description = "metres from a side of the probe's box within which a texel counts as at its border",
       .kind = KnobKind::Real,
       .default_grid = {"0.5"},
       .min_value = 0.0,
       .max_value = 100},
      {.name = "ref_spp",
       .description = "specular-lobe samples per texel of the path-traced reference",
       .kind = KnobKind::Integer,
       .default_grid = {"256"},
       .min_value = 1,
       .max_value = 1 << 20},
  };
}

ReferenceRequest probes_reference_request(const SweepScene&, const KnobSetting& k) {
  ReferenceRequest r;
  r.kind = "probe_glossy_specular";
  r.params = {{"texels_per_m", format_number(k.real("density"))},
              {"spp", std::to_string(k.integer("ref_spp"))},
              {"floor_roughness", format_number(k.real("roughness"))},
              {"camera", "0"},
              {"placement", "visible_surface"}};
  return r;
}

// How deep `p` lies in the box: its distance to the nearest side the surface does not lie
// on (the axes along which the normal `n` is small), negative outside.
float depth_in_box(const ProbeVolume& v, const glm::vec3& p, const glm::vec3& n) {
  float depth = 1e30f;
  for (int i = 0; i < 3; ++i)
    if (std::abs(n[i]) < 0.7f) depth = std::min({depth, p[i] - v.box_min[i], v.box_max[i] - p[i]});
  return depth;
}

// What the forward shader adds at the texel (reflection_probes.glsl, probe_specular): the
// probes whose box (grown by the margin) holds p, each read along the reflection direction
// corrected for parallax (by the captured distances, or the box alone when `box_only`) at lod
// roughness x (levels - 1), or by the lobe's samples at the view when `lobe_samples` > 0
// (probe_lobe_radiance), averaged, times the specular albedo.
// `depth`: the largest depth_in_box over those probes. False where no box holds p.
bool probe_specular(const ReflectionProbeSet& set, const engine::GltfBrdf& brdf, const glm::vec3& p, const glm::vec3& n,
                    const glm::vec3& v, bool box_only, int lobe_samples, glm::vec3& out, float& depth) {
  const glm::vec3 r = glm::reflect(-v, n);
  glm::vec3 sum(0.0f);
  int count = 0;
  depth = -1e30f;
  for (std::size_t i = 0; i < set.probes.size(); ++i) {
    const ProbeVolume& pv = set.probes[i];
    if (glm::any(glm::lessThan(p, pv.box_min - kBoxMarginM)) || glm::any(glm::greaterThan(p, pv.box_max + kBoxMarginM)))
      continue;
    const ProbeCube& cube = set.cubes[i];
    if (lobe_samples > 0) {
      sum += probe_lobe_radiance(cube, brdf, p, n, v, lobe_samples, pv.centre, pv.box_min, pv.box_max, box_only);
    } else {
      const float lod = std::sqrt(brdf.alpha) * static_cast<float>(cube.levels.size() - 1);
      const glm::vec3 d = box_only ? box_projected_direction(p, r, pv.centre, pv.box_min, pv.box_max)
                                   : distance_corrected_direction(cube, p, r, pv.centre, pv.box_min, pv.box_max);
      sum += cube_lookup_trilinear(cube, lod, d);
    }
    depth = std::max(depth, depth_in_box(pv, p, n));
    ++count;
  }
  if (count == 0) return false;
  out = sum / static_cast<float>(count) * engine::gltf_directional_albedo(brdf, glm::dot(n, v)).specular;
  return true;
}

RgbField restricted(const RgbField& f, const std::vector<std::uint8_t>& mask) {
  RgbField out = f;
  out.valid.assign(f.count(), 0);
  for (std::size_t i = 0; i < f.count(); ++i) out.valid[i] = f.is_valid(i) && mask[i] ? 1 : 0;
  return out;
}

// Mean bias of the values over the reference per band of cos(theta_v), as the DLM sweep's.
void add_view_band_bias(const GlossyTexels& g, const std::vector<glm::vec3>& values,
                        const std::vector<std::uint8_t>& mask, const RgbField& reference,
                        std::vector<std::pair<std::string, double>>& extras) {
  constexpr double kBands[] = {0.1, 0.3, 0.6, 1.01};
  for (int b = 0; b < 3; ++b) {
    double sv = 0.0, sr = 0.0;
    for (std::size_t t = 0; t < values.size(); ++t) {
      if (!mask[t] || !reference.is_valid(t)) continue;
      const glm::vec3 v = glm::normalize(g.eye - g.s.texels.position[t]);
      const double c = static_cast<double>(glm::dot(g.s.texels.normal[t], v));
      if (c < kBands[b] || c >= kBands[b + 1]) continue;
      sv += static_cast<double>(values[t].x + values[t].y + values[t].z);
      sr += static_cast<double>(reference.rgb[3 * t] + reference.rgb[3 * t + 1] + reference.rgb[3 * t + 2]);
    }
    char name[48];
    std::snprintf(name, sizeof name, "bias_cos%.1f_%.1f", kBands[b], std::min(kBands[b + 1], 1.0));
    extras.emplace_back(name, sr > 0.0 ? sv / sr - 1.0 : std::nan(""));
  }
}

engine::Result<ReflectionProbeSet> bake_probes(const RunContext& ctx, const BakeInput& input, double& atlas_seconds) {
  auto atlas_settings = light_atlas_preset(ctx.knobs.text("atlas"));
  if (!atlas_settings) return atlas_settings.error();
  atlas_settings->seed = ctx.seed;
  atlas_settings->threads = ctx.threads;
  auto atlas = bake_light_atlas(input, *atlas_settings);
  if (!atlas) return atlas.error();
  atlas_seconds = atlas->stats.total_seconds;
  ReflectionProbeSettings s;
  s.resolution = static_cast<int>(ctx.knobs.integer("resolution"));
  s.supersample = static_cast<int>(ctx.knobs.integer("supersample"));
  s.prefilter_samples = static_cast<int>(ctx.knobs.integer("prefilter"));
  s.seed = ctx.seed;
  s.threads = ctx.threads;
  const ProbeAtlas source{&atlas->layout, atlas->width, atlas->height, atlas->irradiance,
                          atlas->settings.include_direct};
  return bake_reflection_probes(input, source, s);
}

engine::Result<MethodOutput> run_reflection_probes(const RunContext& ctx) {
  const double roughness = ctx.knobs.real("roughness");
  const engine::Scene scene = engine::instantiate(with_floor_roughness(ctx.scene.asset, roughness));
  double atlas_seconds = 0.0;
  auto set = bake_probes(ctx, bake_input_from(scene), atlas_seconds);
  if (!set) return set.error();
  // Samples where a camera sees the floor (not on the line where the walls begin): the
  // forward pass evaluates the probes at pixels, and the reference's lobe rays from a
  // border texel's raster sample slip behind the wall (a 0 truth under a lit probe).
  auto g = glossy_texels(ctx.scene, ctx.knobs.real("density"), roughness, nullptr, TexelPlacement::VisibleSurface);
  if (!g) return g.error();
  const AtlasTexels& tex = g->s.texels;
  if (tex.width != ctx.reference.width || tex.height != ctx.reference.height)
    return engine::Error{.message = "the glossy texels' layout differs from the reference's"};
  const float border = static_cast<float>(ctx.knobs.real("border"));
  std::vector<glm::vec3> values(tex.valid.size(), glm::vec3(0.0f));
  std::vector<std::uint8_t> covered(tex.valid.size(), 0), inner(tex.valid.size(), 0), edge(tex.valid.size(), 0);
  std::size_t uncovered = 0;
  const bool box_only = ctx.knobs.text("parallax") == "box";
  const int lobe_samples = ctx.knobs.text("lobe") == "fis" ? static_cast<int>(ctx.knobs.integer("lobe_samples")) : 0;
  for (std::size_t t = 0; t < tex.valid.size(); ++t) {
    if (!g->glossy[t]) continue;
    float depth = 0.0f;
    const glm::vec3 v = glm::normalize(g->eye - tex.position[t]);
    if (!probe_specular(*set, g->brdf[t], tex.position[t], tex.normal[t], v, box_only, lobe_samples, values[t],
                        depth)) {
      ++uncovered;
      continue;
    }
    covered[t] = 1;
    (depth < border ? edge : inner)[t] = 1;
  }
  MethodOutput out;
  out.field = RgbField::from_texels(tex.width, tex.height, values, covered);
  out.costs.bake_seconds = set->stats.total_seconds;
  // What the runtime uploads: RGBA16F cube maps with every level, and R32F distances.
  for (const ProbeCube& c : set->cubes) {
    for (const std::vector<glm::vec3>& level : c.levels) out.costs.bytes += level.size() * 8u;
    if (!box_only) out.costs.bytes += c.distance.size() * 4u;
  }
  const auto count = [](const std::vector<std::uint8_t>& m) {
    return static_cast<double>(std::count(m.begin(), m.end(), std::uint8_t{1}));
  };
  out.extras = {{"volume_truth_rel_rmse", compare_rgb(restricted(out.field, inner), ctx.reference).truth_rel_rmse},
                {"border_truth_rel_rmse", compare_rgb(restricted(out.field, edge), ctx.reference).truth_rel_rmse},
                {"volume_texels", count(inner)},
                {"border_texels", count(edge)},
                {"uncovered_texels", static_cast<double>(uncovered)},
                {"probes", static_cast<double>(set->probes.size())},
                {"capture_seconds", set->stats.capture_seconds},
                {"prefilter_seconds", set->stats.prefilter_seconds},
                {"atlas_seconds", atlas_seconds}};
  add_view_band_bias(*g, values, covered, ctx.reference, out.extras);
  return out;
}

}  // namespace

void register_reflection_probes_sweep(SweepRegistry& registry) {
  registry.add_reference_provider(
      {.kind = "probe_glossy_specular", .version = "pt-2", .compute = [](const ReferenceJob& job) {
         return glossy_specular_truth(job, LobeRadiance::Full);
       }});
  SweepMethod m;
  m.name = method_descriptor(EffectMethod::ReflectionProbes).key;  // gi/methods.h
  m.description =
      "reflection probes (Lagarde 2012, Karis 2013): cube resolution x capture x prefilter vs the path-traced "
      "specular radiance of the glossy texels towards camera 0, inside the probes' boxes and at their borders";
  m.knobs = reflection_probes_knobs();
  m.reference_for = probes_reference_request;
  m.run = run_reflection_probes;
  registry.add_method(std::move(m));
}

}  // namespace gi
