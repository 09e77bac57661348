#include "sweep/reflection_probes_sweep.h"

#include <gi/error_metrics.h>
#include <gi/methods.h>

#include <engine/gltf_brdf.h>
#include <engine/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "core/random.h"
#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"
#include "raytrace/scene_adapter.h"
#include "reflection_probes/reflection_probes.h"
#include "sweep/glossy_texels.h"

namespace gi {
namespace {

// The shader's PROBE_BOX_MARGIN_M (engine/shaders/reflection_probes.glsl).
constexpr float kBoxMarginM = kProbeBoxMarginM;

// What the captures read and what the error is measured on: the tail of reflection_probes_knobs' table.
std::vector<KnobSpec> scene_knobs() {
  return {
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

// The placement's knobs: where the probes capture and when a box gets a second viewpoint.
std::vector<KnobSpec> placement_knobs() {
  return {
      {.name = "capture_height",
       .description = "metres above its box's floor each probe is captured at (0: the box's middle, the default; "
                      "ProbePlacementSettings::capture_height)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0.0,
       .max_value = 100},
      {.name = "second_view",
       .description = "a box whose probe does not see more than this share of its floor gets a second probe over "
                      "the hidden part (ProbePlacementSettings::second_view_min_share, the default; 2: never; "
                      "-1: every box, over its middle)",
       .kind = KnobKind::Real,
       .default_grid = {format_number(ProbePlacementSettings{}.second_view_min_share)},
       .min_value = -1.0,
       .max_value = 2},
      {.name = "second_view_height",
       .description = "metres above its box's floor the second viewpoint is captured at "
                      "(ProbePlacementSettings::second_view_height)",
       .kind = KnobKind::Real,
       .default_grid = {format_number(ProbePlacementSettings{}.second_view_height)},
       .min_value = 0.0,
       .max_value = 100},
      {.name = "visibility",
       .description = "each probe's blend weight times whether it saw the shaded point (probe_visibility_weight, "
                      "the default: on; off: by position alone)",
       .kind = KnobKind::Choice,
       .default_grid = {"on"},
       .choices = {"on", "off"}},
  };
}

// The lookup's lobe: its form and its sample counts.
std::vector<KnobSpec> lobe_knobs() {
  return {
      {.name = "lobe",
       .description = "the lookup's lobe: the split sum's (one read along the reflection, isotropic, n = v) or "
                      "filtered importance sampling of the lobe at the view (probe_lobe_radiance)",
       .kind = KnobKind::Choice,
       .default_grid = {"fis"},
       .choices = {"split_sum", "fis", "fis_chain"}},
      {.name = "lobe_samples",
       .description = "GGX samples per probe of the filtered-importance-sampled lookup (lobe=fis)",
       .kind = KnobKind::Integer,
       .default_grid = {format_number(kProbeLobeSamples)},
       .min_value = 1,
       .max_value = kProbeMaxLobeSamples},
      {.name = "lobe_samples_max",
       .description = "the most lobe samples a grazing view takes: lobe_samples doubled while their count times "
                      "cos theta_v stays below lobe_samples (probe_lobe_sample_count; kProbeGrazingLobeSamples, the "
                      "default; lobe_samples or less: the same count at every view)",
       .kind = KnobKind::Integer,
       .default_grid = {format_number(kProbeGrazingLobeSamples)},
       .min_value = 1,
       .max_value = kProbeMaxLobeSamples},
  };
}

// Long because it is one table, one entry per knob with its grid and range, read as a list.
std::vector<KnobSpec> reflection_probes_knobs() {
  std::vector<KnobSpec> knobs = {
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
      {.name = "box_side",
       .description = "the distances' lookup reads the box first where the captured distance at the ray's exit is "
                      "within this fraction of the exit's (kProbeBoxSideTolerance, the default); negative: the search "
                      "alone (the lookup before issue 36's box first)",
       .kind = KnobKind::Real,
       .default_grid = {format_number(kProbeBoxSideTolerance)},
       .min_value = -1.0,
       .max_value = 100},
      {.name = "rim",
       .description = "the box-first side test also on the nearest of the exit's four distance texels, at an "
                      "opening's rim (kProbeRimNearest, the default: on; off: the lookup before it)",
       .kind = KnobKind::Choice,
       .default_grid = {kProbeRimNearest ? "on" : "off"},
       .choices = {"on", "off"}},
      {.name = "opening_bias",
       .description = "levels the lobe's samples read finer where the probe saw beyond its box's side, an opening "
                      "(kProbeOpeningLevelBias, the default; 0: the lookup before it)",
       .kind = KnobKind::Real,
       .default_grid = {format_number(kProbeOpeningLevelBias)},
       .min_value = 0.0,
       .max_value = 8},
      {.name = "level_bias",
       .description = "levels every lobe sample reads finer than its width asks for (kProbeLobeLevelBias, the "
                      "default; 0: the lookup before it)",
       .kind = KnobKind::Real,
       .default_grid = {format_number(kProbeLobeLevelBias)},
       .min_value = 0.0,
       .max_value = 8},
  };
  for (KnobSpec& k : lobe_knobs()) knobs.push_back(std::move(k));
  const std::vector<KnobSpec> rest = {
      {.name = "segments",
       .description = "corridors cut into segments about as long as they are wide, a probe each (on: "
                      "ProbePlacementSettings::corridor_aspect 2; off: one probe per box, the default)",
       .kind = KnobKind::Choice,
       .default_grid = {"off"},
       .choices = {"on", "off"}},
      {.name = "corridor_aspect",
       .description = "boxes whose longer horizontal side is more than this times the shorter one are cut into "
                      "segments, a probe each (ProbePlacementSettings::corridor_aspect; 0: as `segments` says)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0.0,
       .max_value = 100},
      {.name = "estimate",
       .description =
           "what is scored (the diagnosis, docs/reflection_probes.md): runtime (the probes as the "
           "forward pass reads them); trace (the lobe through the capture's own radiance, traced from "
           "the texel: no probe); oracle_level0 / oracle (a probe captured at the texel itself, no "
           "parallax error: its level 0 under the exact lobe / read as the runtime reads); level0 "
           "(the placed probes' level 0 under the exact lobe, each sample parallax-corrected); exact_parallax "
           "(the placed probes without a cube map: each lobe sample's landing point, traced from the "
           "texel, as the probe's centre sees it: what the probes' view of the world alone costs)",
       .kind = KnobKind::Choice,
       .default_grid = {"runtime"},
       .choices = {"runtime", "trace", "oracle_level0", "oracle", "level0", "exact_parallax", "level0_exact_dir"}},
  };
  knobs.insert(knobs.end(), rest.begin(), rest.end());
  for (KnobSpec& k : placement_knobs()) knobs.push_back(std::move(k));
  for (KnobSpec& k : scene_knobs()) knobs.push_back(std::move(k));
  return knobs;
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

// Probe i's weight at p in the blend: its box's (probe_blend_weight), times whether it saw p when
// `visibility` (probe_visibility_weight), as the shader's probe_weight x probe_visibility.
float blend_weight(const ReflectionProbeSet& set, std::size_t i, const glm::vec3& p, bool visibility) {
  return visibility ? probe_visible_blend_weight(set.probes[i], set.cubes[i], p)
                    : probe_blend_weight(set.probes[i], p, kBoxMarginM);
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
// (probe_lobe_radiance), blended by probe_blend_weight (faded across segments), times the specular albedo.
// `depth`: the largest depth_in_box over those probes. False where no box holds p.
bool probe_specular(const ReflectionProbeSet& set, const engine::GltfBrdf& brdf, const glm::vec3& p, const glm::vec3& n,
                    const glm::vec3& v, bool box_only, float box_side, bool rim, int lobe_samples,
                    const std::vector<ProbeCube>* chains, float opening_bias, float level_bias, bool visibility,
                    glm::vec3& out, float& depth) {
  const glm::vec3 r = glm::reflect(-v, n);
  glm::vec3 sum(0.0f);
  float weight = 0.0f;
  depth = -1e30f;
  for (std::size_t i = 0; i < set.probes.size(); ++i) {
    const ProbeVolume& pv = set.probes[i];
    const float w = blend_weight(set, i, p, visibility);
    if (!(w > 0.0f)) continue;
    const ProbeCube& cube = set.cubes[i];
    if (lobe_samples > 0) {
      sum += w * probe_lobe_radiance(cube, brdf, p, n, v, lobe_samples, pv.centre, pv.box_min, pv.box_max, box_only,
                                     chains ? &(*chains)[i] : nullptr, box_side, rim, opening_bias, level_bias);
    } else {
      const float lod = std::sqrt(brdf.alpha) * static_cast<float>(cube.levels.size() - 1);
      const glm::vec3 d =
          box_only ? box_projected_direction(p, r, pv.centre, pv.box_min, pv.box_max)
                   : distance_corrected_direction(cube, p, r, pv.centre, pv.box_min, pv.box_max, box_side, rim);
      sum += w * cube_lookup_trilinear(cube, lod, d);
    }
    depth = std::max(depth, depth_in_box(pv, p, n));
    weight += w;
  }
  if (!(weight > 0.0f)) return false;
  out = sum / weight * engine::gltf_directional_albedo(brdf, glm::dot(n, v)).specular;
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

// The light atlas the captures read and the probes baked from it.
struct BakedProbes {
  LightAtlasBake atlas;
  ReflectionProbeSettings settings;
  ReflectionProbeSet set;
  bool visibility = true;  ///< The knob `visibility`: the blend weighs each probe by whether it saw the point.
  [[nodiscard]] ProbeAtlas source() const {
    return ProbeAtlas{&atlas.layout, atlas.width, atlas.height, atlas.irradiance, atlas.settings.include_direct};
  }
};

// With GI_PROBE_SWEEP_PROBES set: each probe's capture point and box on stderr (where the
// placement put the second viewpoints).
void print_probes(const BakeInput& input, const ReflectionProbeSet& set) {
  if (!std::getenv("GI_PROBE_SWEEP_PROBES")) return;
  auto caster = make_embree_ray_caster(rt_scene_from(input));  // every instance, as the level stands
  for (const ProbeVolume& v : set.probes) {
    const HiddenReceivers h =
        caster ? hidden_receivers(**caster, v, set.settings.placement.receiver_step_m) : HiddenReceivers{};
    std::fprintf(stderr, "probe at (%.2f %.2f %.2f), %d of %d receivers hidden (%.3f), ",
                 static_cast<double>(v.centre.x), static_cast<double>(v.centre.y), static_cast<double>(v.centre.z),
                 h.hidden, h.samples, static_cast<double>(h.share()));
    std::fprintf(stderr, "box (%.2f %.2f %.2f)-(%.2f %.2f %.2f)\n", static_cast<double>(v.box_min.x),
                 static_cast<double>(v.box_min.y), static_cast<double>(v.box_min.z), static_cast<double>(v.box_max.x),
                 static_cast<double>(v.box_max.y), static_cast<double>(v.box_max.z));
  }
}

engine::Result<BakedProbes> bake_probes(const RunContext& ctx, const BakeInput& input) {
  auto atlas_settings = light_atlas_preset(ctx.knobs.text("atlas"));
  if (!atlas_settings) return atlas_settings.error();
  atlas_settings->seed = ctx.seed;
  atlas_settings->threads = ctx.threads;
  auto atlas = bake_light_atlas(input, *atlas_settings);
  if (!atlas) return atlas.error();
  BakedProbes b{std::move(atlas).value(), {}, {}, ctx.knobs.text("visibility") == "on"};
  ReflectionProbeSettings& s = b.settings;
  s.resolution = static_cast<int>(ctx.knobs.integer("resolution"));
  s.supersample = static_cast<int>(ctx.knobs.integer("supersample"));
  s.prefilter_samples = static_cast<int>(ctx.knobs.integer("prefilter"));
  s.seed = ctx.seed;
  s.threads = ctx.threads;
  if (ctx.knobs.text("segments") == "on") s.placement.corridor_aspect = 2.0f;
  if (ctx.knobs.real("corridor_aspect") > 0.0)
    s.placement.corridor_aspect = static_cast<float>(ctx.knobs.real("corridor_aspect"));
  s.placement.capture_height = static_cast<float>(ctx.knobs.real("capture_height"));
  s.placement.second_view_min_share = static_cast<float>(ctx.knobs.real("second_view"));
  s.placement.second_view_height = static_cast<float>(ctx.knobs.real("second_view_height"));
  auto set = bake_reflection_probes(input, b.source(), s);
  if (!set) return set.error();
  b.set = std::move(set).value();
  print_probes(input, b.set);
  return b;
}

// Samples of the exact lobe per texel (the diagnosis's estimates): enough that their noise
// (about 1/sqrt(N) of the reference's at its 1024 samples x 4) stays below the errors compared.
constexpr int kExactLobeSamples = 4096;
constexpr int kTracedLobeSamples = 1024;

// The specular lobe's reflected radiance at a texel by Monte Carlo over the glTF BRDF as the
// reference samples it (ReferenceBrdf, its specular share over the pdf), `incoming(l)` the
// radiance arriving along l; the same random numbers for every estimate of the texel.
template <typename Incoming>
glm::vec3 exact_lobe(const engine::GltfBrdf& brdf, const glm::vec3& n, const glm::vec3& v, std::size_t texel,
                     int samples, const Incoming& incoming) {
  const ReferenceBrdf f{.normal = n, .material = brdf};
  Pcg32 rng = Pcg32::for_item(0x70726f6265ull, texel);
  glm::vec3 sum(0.0f);
  for (int j = 0; j < samples; ++j) {
    const float ul = rng.next_float(), u1 = rng.next_float(), u2 = rng.next_float();
    BrdfSample bs;
    if (!f.sample(v, ul, u1, u2, bs) || !(bs.pdf > 0.0f)) continue;
    const glm::vec3 spec = engine::gltf_eval_cos(brdf, n, v, bs.wi).specular / bs.pdf;
    if (spec != glm::vec3(0.0f)) sum += spec * incoming(bs.wi);
  }
  return sum / static_cast<float>(samples);
}

enum class Estimate { Runtime, Trace, OracleLevel0, Oracle, Level0, ExactParallax, Level0ExactDir };

Estimate estimate_of(const std::string& name) {
  if (name == "trace") return Estimate::Trace;
  if (name == "oracle_level0") return Estimate::OracleLevel0;
  if (name == "oracle") return Estimate::Oracle;
  if (name == "level0") return Estimate::Level0;
  if (name == "exact_parallax") return Estimate::ExactParallax;
  if (name == "level0_exact_dir") return Estimate::Level0ExactDir;
  return Estimate::Runtime;
}

// The diagnosis's `level0` estimate at texel t: the placed probes' level 0 under the exact lobe,
// each direction corrected for parallax as the runtime corrects it, blended as it blends.
glm::vec3 level0_estimate(const BakedProbes& b, const engine::GltfBrdf& brdf, const glm::vec3& p, const glm::vec3& n,
                          const glm::vec3& v, std::size_t t, bool box_only, float box_side, bool rim) {
  glm::vec3 sum(0.0f);
  float weight = 0.0f;
  for (std::size_t i = 0; i < b.set.probes.size(); ++i) {
    const ProbeVolume& pv = b.set.probes[i];
    const float w = blend_weight(b.set, i, p, b.visibility);
    if (!(w > 0.0f)) continue;
    const ProbeCube& cube = b.set.cubes[i];
    sum += w * exact_lobe(brdf, n, v, t, kExactLobeSamples, [&](const glm::vec3& l) {
             const glm::vec3 d =
                 box_only ? box_projected_direction(p, l, pv.centre, pv.box_min, pv.box_max)
                          : distance_corrected_direction(cube, p, l, pv.centre, pv.box_min, pv.box_max, box_side, rim);
             return cube_lookup_trilinear(cube, 0.0f, d);
           });
    weight += w;
  }
  return weight > 0.0f ? sum / weight : glm::vec3(0.0f);
}

// The diagnosis's estimates at texel t (`estimate` not Runtime): see the knob `estimate`.
glm::vec3 diagnosis_estimate(Estimate estimate, const BakedProbes& b, const ProbeCapturer& capturer,
                             const engine::GltfBrdf& brdf, const glm::vec3& p, const glm::vec3& n, const glm::vec3& v,
                             std::size_t t, bool box_only, float box_side, bool rim, int lobe_samples) {
  const glm::vec3 origin = offset_ray_origin(p, n);
  if (estimate == Estimate::Trace)
    return exact_lobe(brdf, n, v, t, kTracedLobeSamples,
                      [&](const glm::vec3& l) { return capturer.radiance(origin, l); });
  if (estimate == Estimate::ExactParallax || estimate == Estimate::Level0ExactDir) {
    glm::vec3 sum(0.0f);
    float weight = 0.0f;
    for (std::size_t i = 0; i < b.set.probes.size(); ++i) {
      const ProbeVolume& pv = b.set.probes[i];
      const float w = blend_weight(b.set, i, p, b.visibility);
      if (!(w > 0.0f)) continue;
      if (estimate == Estimate::Level0ExactDir) {
        sum += w * exact_lobe(brdf, n, v, t, kTracedLobeSamples, [&](const glm::vec3& l) {
                 float distance = -1.0f;
                 (void)capturer.radiance(origin, l, &distance);
                 const glm::vec3 to = distance < 0.0f ? l : origin + distance * l - pv.centre;
                 return cube_lookup_trilinear(b.set.cubes[i], 0.0f, glm::dot(to, to) > 1e-12f ? to : l);
               });
        weight += w;
        continue;
      }
      sum += w * exact_lobe(brdf, n, v, t, kTracedLobeSamples, [&](const glm::vec3& l) {
               float distance = -1.0f;
               const glm::vec3 direct = capturer.radiance(origin, l, &distance);
               if (distance < 0.0f) return direct;  // the sky: the same from anywhere
               const glm::vec3 to = origin + distance * l - pv.centre;
               return glm::dot(to, to) > 1e-12f ? capturer.radiance(pv.centre, glm::normalize(to)) : direct;
             });
      weight += w;
    }
    return weight > 0.0f ? sum / weight : glm::vec3(0.0f);
  }
  if (estimate == Estimate::Level0) return level0_estimate(b, brdf, p, n, v, t, box_only, box_side, rim);
  const ProbeCube cube = capturer.bake_at(origin);
  if (estimate == Estimate::OracleLevel0)
    return exact_lobe(brdf, n, v, t, kExactLobeSamples,
                      [&](const glm::vec3& l) { return cube_lookup_trilinear(cube, 0.0f, l); });
  // The runtime's lookup of a probe centred at the point: every direction reads as it leaves.
  const glm::vec3 albedo = engine::gltf_directional_albedo(brdf, glm::dot(n, v)).specular;
  if (lobe_samples > 0)
    return probe_lobe_radiance(cube, brdf, origin, n, v, lobe_samples, origin, origin, origin, true) * albedo;
  const float lod = std::sqrt(brdf.alpha) * static_cast<float>(cube.levels.size() - 1);
  return cube_lookup_trilinear(cube, lod, glm::reflect(-v, n)) * albedo;
}

// With GI_PROBE_SWEEP_DUMP set to a file: one CSV row per scored texel appended to it (the
// diagnosis's per-texel maps): the run's knobs, the texel's position, inside (1) or border
// (0), the reference's and the estimate's radiance (RGB summed).
void dump_texels(const RunContext& ctx, const AtlasTexels& tex, const std::vector<glm::vec3>& values,
                 const std::vector<std::uint8_t>& inner, const std::vector<std::uint8_t>& covered) {
  const char* path = std::getenv("GI_PROBE_SWEEP_DUMP");
  if (!path || !*path) return;
  std::FILE* f = std::fopen(path, "a");
  if (!f) return;
  const std::string label = ctx.knobs.text("estimate") + "," + ctx.knobs.text("lobe") + "," +
                            std::to_string(ctx.knobs.integer("lobe_samples")) + "," +
                            std::to_string(ctx.knobs.integer("resolution")) + "," +
                            format_number(ctx.knobs.real("roughness"));
  for (std::size_t t = 0; t < values.size(); ++t) {
    if (!covered[t] || !ctx.reference.is_valid(t)) continue;
    const glm::vec3& q = tex.position[t];
    const float truth = ctx.reference.rgb[3 * t] + ctx.reference.rgb[3 * t + 1] + ctx.reference.rgb[3 * t + 2];
    std::fprintf(f, "%s,%.3f,%.3f,%.3f,%d,%.6g,%.6g\n", label.c_str(), static_cast<double>(q.x),
                 static_cast<double>(q.y), static_cast<double>(q.z), inner[t] ? 1 : 0, static_cast<double>(truth),
                 static_cast<double>(values[t].x + values[t].y + values[t].z));
  }
  std::fclose(f);
}

// With GI_PROBE_SWEEP_DIRS set to a file: per covered texel and probe holding it, one CSV row
// appended: the texel's position, inside (1) or border (0), the probe's centre and box, the
// mirror direction's exact hit (traced) and the lookup's direction, the angle between the
// lookup's and the hit's directions from the probe (degrees), the captured distance in the
// hit's direction against the hit's distance from the probe (the per-texel diagnosis of the
// lookup's directions, docs/reflection_probes.md).
void write_directions(const BakedProbes& b, const ProbeCapturer& capturer, const GlossyTexels& g,
                      const std::vector<std::uint8_t>& covered, const std::vector<std::uint8_t>& inner, float box_side,
                      bool rim) {
  std::FILE* f = std::fopen(std::getenv("GI_PROBE_SWEEP_DIRS"), "a");
  if (!f) return;
  const AtlasTexels& tex = g.s.texels;
  for (std::size_t t = 0; t < tex.valid.size(); ++t) {
    if (!covered[t]) continue;
    const glm::vec3 p = tex.position[t], n = tex.normal[t];
    const glm::vec3 r = glm::reflect(-glm::normalize(g.eye - p), n);
    float distance = -1.0f;
    (void)capturer.radiance(offset_ray_origin(p, n), r, &distance);
    const glm::vec3 hit = distance < 0.0f ? p + 1e4f * r : p + distance * r;
    for (std::size_t i = 0; i < b.set.probes.size(); ++i) {
      const ProbeVolume& pv = b.set.probes[i];
      if (!(probe_blend_weight(pv, p, kBoxMarginM) > 0.0f)) continue;
      const ProbeCube& cube = b.set.cubes[i];
      const glm::vec3 d = distance_corrected_direction(cube, p, r, pv.centre, pv.box_min, pv.box_max, box_side, rim);
      const glm::vec3 to = hit - pv.centre;
      const float cos_a = glm::dot(glm::normalize(d), glm::normalize(to));
      const float angle = std::acos(std::clamp(cos_a, -1.0f, 1.0f)) * 57.29578f;
      const glm::vec3 l_exact = cube_lookup_trilinear(cube, 0.0f, to), l_got = cube_lookup_trilinear(cube, 0.0f, d);
      std::fprintf(f,
                   "%.3f,%.3f,%.3f,%d,%zu,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.4f,%.4f,%.4f,%."
                   "3f,%.3f,%.5g,%.5g\n",
                   static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z), inner[t] ? 1 : 0, i,
                   static_cast<double>(pv.centre.x), static_cast<double>(pv.centre.y), static_cast<double>(pv.centre.z),
                   static_cast<double>(pv.box_min.x), static_cast<double>(pv.box_min.y),
                   static_cast<double>(pv.box_min.z), static_cast<double>(pv.box_max.x),
                   static_cast<double>(pv.box_max.y), static_cast<double>(pv.box_max.z), static_cast<double>(hit.x),
                   static_cast<double>(hit.y), static_cast<double>(hit.z), static_cast<double>(d.x / glm::length(d)),
                   static_cast<double>(d.y / glm::length(d)), static_cast<double>(d.z / glm::length(d)),
                   static_cast<double>(angle), static_cast<double>(cube_distance_bilinear(cube, to) - glm::length(to)),
                   static_cast<double>(l_exact.x + l_exact.y + l_exact.z),
                   static_cast<double>(l_got.x + l_got.y + l_got.z));
    }
  }
  std::fclose(f);
}

engine::Status dump_directions(const BakedProbes& b, const BakeInput& input, const GlossyTexels& g,
                               const std::vector<std::uint8_t>& covered, const std::vector<std::uint8_t>& inner,
                               float box_side, bool rim) {
  const char* path = std::getenv("GI_PROBE_SWEEP_DIRS");
  if (!path || !*path) return {};
  auto capturer = ProbeCapturer::make(input, b.source(), b.settings);
  if (!capturer) return capturer.error();
  write_directions(b, *capturer, g, covered, inner, box_side, rim);
  return {};
}

// With the knob `estimate` other than runtime: `values` at the covered texels replaced by the
// diagnosis's estimate.
engine::Status diagnose(const RunContext& ctx, const BakedProbes& baked, const BakeInput& input, const GlossyTexels& g,
                        const std::vector<std::uint8_t>& covered, bool box_only, float box_side, bool rim,
                        int lobe_samples, int lobe_max, std::vector<glm::vec3>& values) {
  const Estimate estimate = estimate_of(ctx.knobs.text("estimate"));
  if (estimate == Estimate::Runtime) return {};
  auto capturer = ProbeCapturer::make(input, baked.source(), baked.settings);
  if (!capturer) return capturer.error();
  const AtlasTexels& tex = g.s.texels;
  ThreadPool pool(ctx.threads);
  pool.parallel_for(tex.valid.size(), [&](std::size_t t) {
    if (!covered[t]) return;
    const glm::vec3 v = glm::normalize(g.eye - tex.position[t]);
    values[t] = diagnosis_estimate(
        estimate, baked, *capturer, g.brdf[t], tex.position[t], tex.normal[t], v, t, box_only, box_side, rim,
        lobe_samples > 0 ? probe_lobe_sample_count(lobe_samples, lobe_max, glm::dot(tex.normal[t], v)) : 0);
  });
  return {};
}

// With lobe=fis_chain: each probe's box-filtered chain, which the lobe's samples read; else none.
std::vector<ProbeCube> lookup_chains(const RunContext& ctx, const ReflectionProbeSet& set) {
  std::vector<ProbeCube> chains;
  if (ctx.knobs.text("lobe") == "fis_chain")
    for (const ProbeCube& c : set.cubes) chains.push_back(box_filtered_chain(c));
  return chains;
}

// What the runtime uploads: RGBA16F cube maps with every level, and R32F distances.
std::size_t gpu_bytes(const ReflectionProbeSet& set, bool box_only) {
  std::size_t bytes = 0;
  for (const ProbeCube& c : set.cubes) {
    for (const std::vector<glm::vec3>& level : c.levels) bytes += level.size() * 8u;
    if (!box_only) bytes += c.distance.size() * 4u;
  }
  return bytes;
}

// The run's extras: the error inside the probes' volumes and at their borders, the texel counts
// and the bake's parts.
std::vector<std::pair<std::string, double>> run_extras(const RgbField& field, const RunContext& ctx,
                                                       const std::vector<std::uint8_t>& inner,
                                                       const std::vector<std::uint8_t>& edge, std::size_t uncovered,
                                                       const BakedProbes& baked) {
  const auto count = [](const std::vector<std::uint8_t>& m) {
    return static_cast<double>(std::count(m.begin(), m.end(), std::uint8_t{1}));
  };
  const ReflectionProbeSet& set = baked.set;
  return {{"volume_truth_rel_rmse", compare_rgb(restricted(field, inner), ctx.reference).truth_rel_rmse},
          {"border_truth_rel_rmse", compare_rgb(restricted(field, edge), ctx.reference).truth_rel_rmse},
          {"volume_texels", count(inner)},
          {"border_texels", count(edge)},
          {"uncovered_texels", static_cast<double>(uncovered)},
          {"probes", static_cast<double>(set.probes.size())},
          {"capture_seconds", set.stats.capture_seconds},
          {"prefilter_seconds", set.stats.prefilter_seconds},
          {"atlas_seconds", baked.atlas.stats.total_seconds}};
}

engine::Result<MethodOutput> run_reflection_probes(const RunContext& ctx) {
  const double roughness = ctx.knobs.real("roughness");
  const engine::Scene scene = engine::instantiate(with_floor_roughness(ctx.scene.asset, roughness));
  const BakeInput input = bake_input_from(scene);
  auto baked = bake_probes(ctx, input);
  if (!baked) return baked.error();
  const ReflectionProbeSet* set = &baked->set;
  // Samples where a camera sees the floor, as the forward pass's pixels (a border texel's raster
  // sample lies on the line where the walls begin, and the reference's rays slip behind them).
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
  const auto box_side = static_cast<float>(ctx.knobs.real("box_side"));
  const bool rim = ctx.knobs.text("rim") == "on";
  const int lobe_samples =
      ctx.knobs.text("lobe") != "split_sum" ? static_cast<int>(ctx.knobs.integer("lobe_samples")) : 0;
  const auto lobe_max = static_cast<int>(ctx.knobs.integer("lobe_samples_max"));
  const std::vector<ProbeCube> chains = lookup_chains(ctx, *set);
  const auto opening_bias = static_cast<float>(ctx.knobs.real("opening_bias"));
  const auto level_bias = static_cast<float>(ctx.knobs.real("level_bias"));
  for (std::size_t t = 0; t < tex.valid.size(); ++t) {
    if (!g->glossy[t]) continue;
    float depth = 0.0f;
    const glm::vec3 v = glm::normalize(g->eye - tex.position[t]);
    const int samples =
        lobe_samples > 0 ? probe_lobe_sample_count(lobe_samples, lobe_max, glm::dot(tex.normal[t], v)) : 0;
    if (!probe_specular(*set, g->brdf[t], tex.position[t], tex.normal[t], v, box_only, box_side, rim, samples,
                        chains.empty() ? nullptr : &chains, opening_bias, level_bias, baked->visibility, values[t],
                        depth)) {
      ++uncovered;
      continue;
    }
    covered[t] = 1;
    (depth < border ? edge : inner)[t] = 1;
  }
  if (auto diagnosed =
          diagnose(ctx, *baked, input, *g, covered, box_only, box_side, rim, lobe_samples, lobe_max, values);
      !diagnosed)
    return diagnosed.error();
  dump_texels(ctx, tex, values, inner, covered);
  if (auto dumped = dump_directions(*baked, input, *g, covered, inner, box_side, rim); !dumped) return dumped.error();
  MethodOutput out;
  out.field = RgbField::from_texels(tex.width, tex.height, values, covered);
  out.costs.bake_seconds = set->stats.total_seconds;
  out.costs.bytes = gpu_bytes(*set, box_only);
  out.extras = run_extras(out.field, ctx, inner, edge, uncovered, *baked);
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
