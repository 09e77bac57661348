// gi::plan: the rules of DESIGN.md §3 "Effects on demand" over a scene's facts (docs/plan.md).
#include <gi/plan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "antiradiance/element_hierarchy.h"
#include "antiradiance/near_door_visibility.h"
#include "brf/brf_bake.h"
#include "plan/plan_cost.h"
#include "plan/static_surface_census.h"

namespace gi {

namespace {

// What this build can bake (gi-bake --methods): every method.
constexpr bool kAvailable[kEffectMethodCount] = {true, true, true, true, true, true};

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// "a, b, c" (at most `shown`, then "and N more").
std::string list_names(const std::vector<std::string>& names, std::size_t shown = 4) {
  std::string out;
  for (std::size_t i = 0; i < names.size() && i < shown; ++i) out += (i ? ", " : "") + names[i];
  if (names.size() > shown) out += " and " + std::to_string(names.size() - shown) + " more";
  return out;
}

std::string quoted_list(const std::vector<std::string>& names, std::size_t shown = 3) {
  std::vector<std::string> q;
  for (const std::string& n : names) q.push_back("'" + n + "'");
  return list_names(q, shown);
}

std::string fixed(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string instance_name(const BakeInput& input, std::size_t i) {
  const std::string& n = input.instances[i].name;
  return n.empty() ? "instance " + std::to_string(i) : n;
}

// Why a light moves, or empty: its own flag, the plan options, or a dynamic node it hangs
// from (which the bakers do not see: `only_by_node` says so).
std::string why_light_moves(const BakeLight& l, const std::string& name, const PlanOptions& options,
                            bool* only_by_node) {
  *only_by_node = false;
  if (l.light.moves) return "light_moves";
  if (std::find(options.moving_lights.begin(), options.moving_lights.end(), name) != options.moving_lights.end())
    return "scripted by the game";
  if (!l.dynamic_parent.empty()) {
    *only_by_node = true;
    return l.dynamic_parent == name ? "on a dynamic node" : "hangs from dynamic node '" + l.dynamic_parent + "'";
  }
  return {};
}

bool emissive(const BakeInput& input, const BakeInstance& inst) {
  for (const BakePrimitive& p : input.meshes[inst.mesh].primitives)
    if (glm::length(bake_material(input, inst, p).emission) > 0.0f) return true;
  return false;
}

// The lowest roughness factor among the instance's materials (textures can only lower it
// further: glTF multiplies the factor by the texture), and that material's name.
std::pair<float, std::string> min_roughness(const BakeInput& input, const BakeInstance& inst) {
  std::pair<float, std::string> best{2.0f, {}};
  for (const BakePrimitive& p : input.meshes[inst.mesh].primitives) {
    const BakeMaterial m = bake_material(input, inst, p);
    if (m.roughness < best.first) best = {m.roughness, m.name};
  }
  return best;
}

// What the rules read, gathered once.
struct PlanFacts {
  std::vector<std::string> static_lights, moving_lights, moving_why;
  std::vector<std::string> static_meshes, emissive_meshes, glossy, glossy_why, sharp_glossy, deforming;
  std::vector<std::size_t> glossy_instances;                          // indices into BakeInput::instances
  std::map<std::uint32_t, std::vector<std::string>> dynamic_by_mesh;  // mesh -> instances
  LightPointCount points;
  StaticSurfaceCensus census;
  bool sky = false;  // the environment's sky lights the scene (an outdoor scene)
};

// A static surface by its roughness: in the DLM range, or sharper (the reflection probes' range).
void classify_glossy(PlanFacts& f, const PlanOptions& options, std::size_t i, const std::string& name, float roughness,
                     const std::string& material) {
  const std::string what = "'" + name + "' (" + material + ") ";
  if (roughness < options.glossy_roughness_min) {
    f.sharp_glossy.push_back(what + fixed(roughness, 2));
  } else if (roughness < options.glossy_roughness) {
    f.glossy.push_back(name);
    f.glossy_instances.push_back(i);
    f.glossy_why.push_back(what + "has roughness " + fixed(roughness, 2));
  }
}

PlanFacts gather_facts(const BakeInput& input, const PlanOptions& options, EffectPlan& out) {
  PlanFacts f;
  SceneFacts& facts = out.facts;
  for (std::size_t i = 0; i < input.lights.size(); ++i) {
    const BakeLight& l = input.lights[i];
    if (!l.light.enabled) {
      ++facts.disabled_lights;
      continue;
    }
    const std::string name = l.name.empty() ? "light " + std::to_string(i) : l.name;
    bool only_by_node = false;
    const std::string why = why_light_moves(l, name, options, &only_by_node);
    if (!why.empty()) {
      f.moving_lights.push_back(name);
      f.moving_why.push_back(why);
      if (only_by_node)
        out.warnings.push_back("light '" + name + "' " + why +
                               " but is not flagged light_moves: the light atlas would bake it as static; set "
                               "gi.light_moves");
      continue;
    }
    f.static_lights.push_back(name);
    if (l.light.type == engine::LightType::Area)
      ++f.points.sampled;
    else if (l.light.type == engine::LightType::Directional)
      ++f.points.directional;
    else
      ++f.points.punctual;
  }
  facts.static_lights = static_cast<int>(f.static_lights.size());
  facts.moving_lights = static_cast<int>(f.moving_lights.size());
  f.sky = engine::sky_lit(input.environment.sky_radiance, input.environment.sky_gradient);

  for (std::size_t i = 0; i < input.instances.size(); ++i) {
    const BakeInstance& inst = input.instances[i];
    if (inst.mesh >= input.meshes.size()) continue;
    const std::string name = instance_name(input, i);
    if (inst.deforming) f.deforming.push_back(name);
    if (inst.mobility == BakeMobility::Dynamic) {
      ++facts.dynamic_meshes;
      f.dynamic_by_mesh[inst.mesh].push_back(name);
      continue;
    }
    ++facts.static_meshes;
    f.static_meshes.push_back(name);
    if (emissive(input, inst)) f.emissive_meshes.push_back(name);
    const auto [roughness, material] = min_roughness(input, inst);
    classify_glossy(f, options, i, name, roughness, material);
  }
  facts.emissive_surfaces = static_cast<int>(f.emissive_meshes.size());
  f.points.sampled += 2 * facts.emissive_surfaces;  // emissive quads: two triangles each, typically
  f.census = census_static_surfaces(input);
  facts.static_area_m2 = f.census.area_m2;
  facts.static_albedo = f.census.albedo;
  return f;
}

// The bakers' presets with gi-bake's overrides; nullopt when the preset is unknown.
struct PlanPresets {
  LightAtlasSettings atlas;
  PrmSettings prm;
  DlmSettings dlm;
};
std::optional<PlanPresets> presets(const PlanOptions& options) {
  auto atlas = light_atlas_preset(options.preset);
  auto prm = prm_preset(options.preset);
  auto dlm = dlm_preset(options.preset);
  if (!atlas || !prm || !dlm) return std::nullopt;
  PlanPresets p{*atlas, *prm, *dlm};
  p.dlm.glossy_roughness = options.glossy_roughness;
  p.dlm.glossy_roughness_min = options.glossy_roughness_min;
  if (options.texels_per_metre > 0.0f) {
    p.atlas.texels_per_metre = p.dlm.texels_per_metre = options.texels_per_metre;
    set_prm_atlas_density(p.prm, options.texels_per_metre);
  }
  if (options.vpls > 0) p.atlas.vpl_count = options.vpls;
  if (options.samples_per_vpl > 0) p.atlas.samples_per_vpl = options.samples_per_vpl;
  if (options.bounces > 0) p.atlas.bounces = options.bounces;
  return p;
}

// Light atlas: static light sources on static geometry.
void plan_light_atlas(const PlanFacts& f, const std::optional<PlanPresets>& p, PlannedEffect& atlas) {
  const std::size_t static_sources = f.static_lights.size() + f.emissive_meshes.size() + (f.sky ? 1 : 0);
  if (f.static_meshes.empty()) {
    atlas.reason = "no static mesh: nothing for a light atlas to hold";
    return;
  }
  if (static_sources == 0) {
    atlas.reason =
        "no static light (" + plural(f.moving_lights.size(), "light moves", "lights move") + ") -> no light atlas";
    return;
  }
  atlas.enabled = true;
  const std::string area = fixed(f.census.area_m2, 1) + " m^2";
  const std::string meshes = plural(f.static_meshes.size(), "static mesh", "static meshes");
  const std::string emitting = plural(f.emissive_meshes.size(), "emissive surface", "emissive surfaces");
  const std::string sky = f.sky ? "; the sky too" : "";
  if (f.static_lights.empty() && f.emissive_meshes.empty()) {
    atlas.reason = "the sky lights " + meshes + " (" + area + ")";
  } else if (f.static_lights.empty()) {
    atlas.reason =
        emitting + (f.emissive_meshes.size() == 1 ? " lights " : " light ") + meshes + " (" + area + sky + ")";
  } else {
    atlas.reason = plural(f.static_lights.size(), "static light", "static lights") +
                   (f.static_lights.size() == 1 ? " lights " : " light ") + meshes + " (" + area +
                   (f.emissive_meshes.empty() ? "" : "; " + emitting + " too") + sky + ")";
  }
  atlas.targets = f.static_meshes;
  if (!p) return;
  const BakeWork w = light_atlas_work(f.census, p->atlas, f.points);
  const AtlasTexelEstimate t = atlas_texels(f.census, p->atlas.texels_per_metre);
  atlas.estimate = {
      w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(t.lit_texels),
      fixed(f.census.area_m2, 1) + " m^2 x " + fixed(p->atlas.texels_per_metre, 0) + "^2 texels/m^2 -> ~" +
          std::to_string(static_cast<long long>(t.lit_texels)) + " texels (atlas " + std::to_string(t.width) + "x" +
          std::to_string(t.height) + ") x " +
          (p->atlas.final_pass == LightAtlasSettings::FinalPass::TexelGather
               ? std::to_string(p->atlas.gather.solve_rays) + " kept + " + std::to_string(p->atlas.gather.gather_rays) +
                     " gather" +
                     (p->atlas.gather.emitter_rays > 0
                          ? " + " + std::to_string(p->atlas.gather.emitter_rays) + " emitter-sampled"
                          : std::string()) +
                     " rays" +
                     (p->atlas.gather.near_regather_rays > 0
                          ? " (landings nearer than a texel: " + std::to_string(p->atlas.gather.near_regather_rays) +
                                " more" +
                                (p->atlas.gather.near_regather_depth > 1
                                     ? ", theirs " + std::to_string(p->atlas.gather.near_regather_deep_rays) + " more"
                                     : std::string()) +
                                ")"
                          : std::string()) +
                     (p->atlas.gather.adaptive_share > 0.0f
                          ? ", the noisiest " + fixed(100.0 * double{p->atlas.gather.adaptive_share}, 0) +
                                "% of the texels x " + std::to_string(1 + p->atlas.gather.adaptive_passes)
                          : std::string())
               : std::to_string(p->atlas.vpl_count) + " VPLs, " + std::to_string(p->atlas.bounces) + " bounces")};
}

// PRM: moving lights over static geometry.
void plan_prm(const PlanFacts& f, const std::optional<PlanPresets>& p, PlannedEffect& prm) {
  if (f.moving_lights.empty()) {
    prm.reason = "no light moves -> no PRM panes";
    return;
  }
  if (f.static_meshes.empty()) {
    prm.reason = "lights move but there is no static mesh to relight";
    return;
  }
  prm.enabled = true;
  std::vector<std::string> parts;
  for (std::size_t i = 0; i < f.moving_lights.size() && i < 3; ++i)
    parts.push_back("light '" + f.moving_lights[i] + "' moves (" + f.moving_why[i] + ")");
  prm.reason =
      list_names(parts, 3) + " -> PRM panes over " + plural(f.static_meshes.size(), "static mesh", "static meshes");
  prm.targets = f.static_meshes;
  if (!p) return;
  double nodes = 0.0;
  const BakeWork w = prm_work(f.census, p->prm, &nodes);
  const AtlasTexelEstimate t = atlas_texels(f.census, pane_density(p->prm));
  prm.estimate = {
      w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(nodes),
      std::to_string(p->prm.entry_points) + " entry points x N_s " + fixed(p->prm.splitting, 0) + " at albedo " +
          fixed(f.census.albedo, 2) + " -> ~" + std::to_string(static_cast<long long>(nodes)) + " path nodes x ~" +
          std::to_string(static_cast<long long>(coarse_panes(p->prm) ? t.footprint_texels : t.pane_texels)) +
          " pane texels; " + std::to_string(p->prm.clusters) +
          (coarse_panes(p->prm) ? " panes as RGB9E5 at " : " panes as half floats at ") +
          fixed(pane_density(p->prm), 0) + " texels/m"};
}

// Directional light maps: glossy static surfaces.
void plan_dlm(const BakeInput& input, const PlanFacts& f, const PlanOptions& options,
              const std::optional<PlanPresets>& p, PlannedEffect& dlm) {
  const std::string threshold = fixed(options.glossy_roughness, 2);
  const std::string range = "[" + fixed(options.glossy_roughness_min, 2) + ", " + threshold + ")";
  // Sharper surfaces: the reflection probes' range (their lobe is narrower than a bin).
  const std::string sharp = f.sharp_glossy.empty()
                                ? std::string()
                                : "; sharper than " + fixed(options.glossy_roughness_min, 2) +
                                      " (reflection probes' range): " + list_names(f.sharp_glossy, 2);
  if (f.glossy.empty()) {
    dlm.reason = "no static surface has roughness in " + range + " -> no directional maps" + sharp;
    return;
  }
  dlm.enabled = true;
  // The maps hold the static lights' and emissive surfaces' indirect light only (gi/src/dlm/dlm.h).
  dlm.reason = "static surface " + list_names(f.glossy_why, 2) + " in " + range + sharp +
               " -> directional light maps (static lights only: moving lights and the sky are absent from them, "
               "their indirect light stays direction-less in the atlas term)";
  dlm.targets = f.glossy;
  if (!p) return;
  // The glossy instances' own charts: the texels that get a map per direction.
  BakeInput glossy_only;
  glossy_only.meshes = input.meshes;
  glossy_only.materials = input.materials;
  for (std::size_t i : f.glossy_instances) glossy_only.instances.push_back(input.instances[i]);
  const StaticSurfaceCensus glossy = census_static_surfaces(glossy_only);
  double texels = 0.0, per_texel = 0.0;
  const BakeWork w =
      dlm_work(glossy, f.census.albedo, atlas_texels(f.census, p->dlm.texels_per_metre), p->dlm, &texels, &per_texel);
  dlm.estimate = {w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(texels),
                  fixed(glossy.area_m2, 1) + " m^2 glossy -> ~" + std::to_string(static_cast<long long>(texels)) +
                      " texels x " + std::to_string(p->dlm.directions) +
                      " directions x 8 B = " + format_bytes(static_cast<std::uint64_t>(per_texel)) + " per texel; " +
                      std::to_string(p->dlm.photons) + " photons"};
}

// Reflection probes: static surfaces smoother than the directional light maps' bins can
// carry (roughness < kReflectionProbeMaxRoughness), and the dynamic objects that then read
// them too. The probe count is estimated as one per 80 m^2 of static surface (a 4 x 3 x 4 m
// room's floor, ceiling and walls); the bake places them (docs/reflection_probes.md).
void plan_reflection_probes(const BakeInput& input, const PlanFacts& f, const PlanOptions& options,
                            const PlannedEffect& atlas, PlannedEffect& probes) {
  const std::string threshold = fixed(kReflectionProbeMaxRoughness, 2);
  std::vector<std::string> sharp, why;
  for (std::size_t i = 0; i < input.instances.size(); ++i) {
    const BakeInstance& inst = input.instances[i];
    if (inst.mesh >= input.meshes.size() || inst.mobility == BakeMobility::Dynamic) continue;
    const auto [roughness, material] = min_roughness(input, inst);
    if (roughness >= kReflectionProbeMaxRoughness) continue;
    sharp.push_back(instance_name(input, i));
    why.push_back("'" + sharp.back() + "' (" + material + ") has roughness " + fixed(roughness, 2));
  }
  if (sharp.empty()) {
    probes.reason = "no static surface has roughness < " + threshold + " -> no reflection probes";
    return;
  }
  if (!atlas.enabled) {
    probes.reason = "static surface " + list_names(why, 2) + " < " + threshold +
                    ", but the probes capture the light atlas's light and there is none -> no reflection probes";
    return;
  }
  probes.enabled = true;
  probes.reason = "static surface " + list_names(why, 2) + " < " + threshold +
                  " -> reflection probes (box-projected cube maps, also read by dynamic objects)";
  probes.targets = sharp;
  const auto preset = reflection_probe_preset(options.preset);
  if (!preset) return;
  const ReflectionProbeSettings& s = *preset;
  const auto count = static_cast<std::size_t>(std::max(1.0, std::round(f.census.area_m2 / 80.0)));
  const int light_points = f.points.punctual + f.points.directional + f.points.sampled * s.area_light_samples;
  const BakeWork w = reflection_probes_work(count, s, light_points);
  probes.estimate = {w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(w.units),
                     "~" + std::to_string(count) + " probes (" + fixed(f.census.area_m2, 0) + " m^2 / 80 m^2) x 6 x " +
                         std::to_string(s.resolution) + "^2 texels x " + std::to_string(s.supersample * s.supersample) +
                         " rays; RGBA16F with mips, R32F distances " + std::to_string(kProbeDistanceScale) + "x finer"};
}

// Near-door visibility (antiradiance's preset setting): its receivers as NearDoorVisibility
// picks them (near_door_receivers: the radius of each deforming instance's reach, then the
// budget), its
// memory added to the estimate, its load work and per-move cost in the basis.
void add_near_visibility(const BakeInput& input, const ElementHierarchy& h, const AntiradianceSettings& s,
                         EffectEstimate& e) {
  std::size_t receivers = 0;
  for (std::uint32_t door : h.deforming_instances) {
    const std::vector<char> mask = near_door_receivers(input, h, door, near_door_settings(s));
    receivers += static_cast<std::size_t>(std::count(mask.begin(), mask.end(), char{1}));
  }
  double move_seconds = 0.0;
  const BakeWork w = near_visibility_work(h.leaf_count(), receivers, s, &move_seconds);
  // Not baked (a load computes the couplings: storing them would be their 12 bytes per pair),
  // so no bake seconds; the memory is the runtime's largest item for the region (CPU-side,
  // counted here unlike the links' CPU copy: it grows with the square of the leaves).
  e.runtime_bytes += w.runtime_bytes;
  e.basis += "; near-door visibility: " + std::to_string(receivers) + " receivers x " + std::to_string(h.leaf_count()) +
             " leaves, ~" + fixed(w.units * 1e-6, 1) + " M pairs at load (~" + fixed(w.cpu_seconds, 1) + " s), ~" +
             fixed(move_seconds, 1) + " s per door move, " + format_bytes(w.runtime_bytes) + " CPU";
}

// Antiradiance: flagged deforming or opening regions.
void plan_antiradiance(const BakeInput& input, const PlanFacts& f, const PlanOptions& options, bool known_preset,
                       PlannedEffect& anti) {
  if (f.deforming.empty()) {
    anti.reason = "no node is flagged gi.region \"deforming\" -> no antiradiance";
    return;
  }
  anti.enabled = true;
  anti.reason = plural(f.deforming.size(), "mesh is", "meshes are") + " flagged gi.region \"deforming\" (" +
                quoted_list(f.deforming) + ") -> antiradiance for that region";
  anti.targets = f.deforming;
  if (!known_preset) return;
  // The elements as the bake builds them (cheap: triangle pieces and a cluster tree); the
  // links, the bake time and the GPU bytes from the cost model.
  const AntiradianceSettings s = antiradiance_preset(options.preset);
  auto h = build_element_hierarchy(input, s);
  if (!h) return;
  double links = 0.0, file = 0.0;
  const BakeWork w = antiradiance_work(h->nodes.size(), h->leaf_count(), s, &links, &file);
  anti.estimate = {w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(links),
                   std::to_string(h->nodes.size()) + " elements (" + std::to_string(h->leaf_count()) + " leaves of " +
                       fixed(s.patch_size_m, 1) + " m) x " + std::to_string(s.bins_per_side * s.bins_per_side) +
                       " bins -> ~" + fixed(links * 1e-6, 1) + " M links; GPU tables + links; file ~" +
                       format_bytes(static_cast<std::uint64_t>(file))};
  if (s.near_visibility) add_near_visibility(input, *h, s, anti.estimate);
}

// Basis radiance fields: the meshes of dynamic instances, once per mesh.
void plan_brf(const BakeInput& input, const PlanFacts& f, const PlanOptions& options, int dynamic_instances,
              PlannedEffect& brf) {
  if (f.dynamic_by_mesh.empty()) {
    brf.reason = "no dynamic mesh -> no basis radiance fields";
    return;
  }
  brf.enabled = true;
  std::vector<std::string> mesh_names, glossy_meshes;
  std::size_t vertices = 0;
  BakeWork total;
  const auto brf_settings = brf_preset(options.preset);
  const PcaBasisSettings basis = brf_settings ? brf_settings->basis : PcaBasisSettings{};
  const RadianceFieldSettings field = brf_settings ? brf_settings->field : RadianceFieldSettings{};
  for (const auto& [mesh, users] : f.dynamic_by_mesh) {
    const BakeMesh& m = input.meshes[mesh];
    mesh_names.push_back(m.name.empty() ? "mesh " + std::to_string(mesh) : m.name);
    std::size_t v = 0, t = 0;
    for (const BakePrimitive& p : m.primitives) v += p.positions.size(), t += p.indices.size() / 3;
    vertices += v;
    // A glossy material (brf_glossy_lobe) multiplies the field by 1 + its terms; the
    // separation may keep one more term to keep an azimuthal pair whole.
    const bool is_glossy = !m.primitives.empty() &&
                           brf_glossy_lobe(bake_material(input, BakeInstance{}, m.primitives.front())).has_value();
    const int terms = is_glossy ? 2 + (brf_settings ? brf_settings->glossy.terms : 4) : 1;
    if (is_glossy) glossy_meshes.push_back(mesh_names.back());
    const BakeWork w = brf_work(v, t, basis, field, terms);
    total.bake_seconds += w.bake_seconds;
    total.runtime_bytes += w.runtime_bytes;
    total.units += w.units;
  }
  brf.reason =
      plural(static_cast<std::size_t>(dynamic_instances), "dynamic entity uses ", "dynamic entities use ") +
      plural(mesh_names.size(), "mesh", "meshes") + " (" + list_names(mesh_names) +
      ") -> a basis and a field per mesh" +
      (glossy_meshes.empty() ? std::string()
                             : "; glossy metal (" + list_names(glossy_meshes) + ") -> its lobe in separable terms");
  brf.targets = mesh_names;
  brf.estimate = {total.bake_seconds, total.runtime_bytes, static_cast<std::uint64_t>(total.units),
                  std::to_string(mesh_names.size()) + " meshes, " + std::to_string(vertices) + " vertices; per mesh " +
                      std::to_string(field.spheres) + " spheres x 6 x " + std::to_string(field.face_resolution) +
                      "^2 points x " + std::to_string(basis.basis) + " functions x " +
                      std::to_string(field.sh_bands * field.sh_bands) + " SH coefficients x 4 B, " +
                      std::to_string(field.directions) + " rays per point (brf_preset)"};
}

std::string estimate_line(double seconds, std::uint64_t bytes) {
  return "~" + format_seconds(seconds) + " bake, ~" + format_bytes(bytes) + " at runtime";
}

}  // namespace

std::string_view effect_key(EffectMethod method) { return method_descriptor(method).key; }

std::optional<EffectMethod> effect_from_key(std::string_view key) { return method_from_key(key); }

const PlannedEffect& EffectPlan::effect(EffectMethod method) const {
  for (const PlannedEffect& e : effects)
    if (e.method == method) return e;
  static const PlannedEffect none{};
  return none;
}

std::vector<std::string> EffectPlan::methods_to_bake() const {
  std::vector<std::string> out;
  for (const PlannedEffect& e : effects)
    if (e.enabled && e.available) out.emplace_back(effect_key(e.method));
  return out;
}

std::string format_seconds(double s) {
  if (s < 1.0) return std::to_string(static_cast<int>(std::max(1.0, s * 1000.0 + 0.5))) + " ms";
  if (s < 100.0) return fixed(s, 1) + " s";
  if (s < 6000.0) return fixed(s / 60.0, 1) + " min";
  return fixed(s / 3600.0, 1) + " h";
}

std::string format_bytes(std::uint64_t b) {
  const double v = static_cast<double>(b);
  if (v < 1e3) return std::to_string(b) + " B";
  if (v < 1e6) return fixed(v / 1e3, 1) + " kB";
  if (v < 1e9) return fixed(v / 1e6, 1) + " MB";
  return fixed(v / 1e9, 2) + " GB";
}

EffectPlan plan(const BakeInput& input, const PlanOptions& options) {
  EffectPlan out;
  out.scene = input.name;
  out.preset = options.preset;
  out.glossy_roughness = options.glossy_roughness;
  out.glossy_roughness_min = options.glossy_roughness_min;
  for (int i = 0; i < kEffectMethodCount; ++i) {
    PlannedEffect e;
    e.method = static_cast<EffectMethod>(i);
    e.available = kAvailable[i];
    out.effects.push_back(std::move(e));
  }
  const PlanFacts f = gather_facts(input, options, out);
  const std::optional<PlanPresets> p = presets(options);
  if (!p) out.warnings.push_back("unknown preset '" + options.preset + "' (preview, medium, high): no estimates");

  if (f.static_lights.empty() && f.moving_lights.empty() && f.emissive_meshes.empty() && !f.sky) {
    const std::string why =
        out.facts.disabled_lights > 0
            ? "no light is on (" +
                  plural(static_cast<std::size_t>(out.facts.disabled_lights), "light is", "lights are") +
                  " switched off) and no surface is emissive: nothing to bake"
            : "the scene has no light and no emissive surface: nothing to bake";
    for (PlannedEffect& e : out.effects) e.reason = why;
    return out;
  }
  plan_light_atlas(f, p, out.effects[static_cast<int>(EffectMethod::LightAtlas)]);
  plan_prm(f, p, out.effects[static_cast<int>(EffectMethod::Prm)]);
  plan_dlm(input, f, options, p, out.effects[static_cast<int>(EffectMethod::DirectionalLightMaps)]);
  plan_antiradiance(input, f, options, p.has_value(), out.effects[static_cast<int>(EffectMethod::Antiradiance)]);
  plan_brf(input, f, options, out.facts.dynamic_meshes,
           out.effects[static_cast<int>(EffectMethod::BasisRadianceFields)]);
  plan_reflection_probes(input, f, options, out.effects[static_cast<int>(EffectMethod::LightAtlas)],
                         out.effects[static_cast<int>(EffectMethod::ReflectionProbes)]);
  for (PlannedEffect& e : out.effects)
    if (!e.enabled || !e.available) e.estimate = {};
  return out;
}

EffectPlan plan(const engine::Scene& scene, const PlanOptions& options) {
  return plan(bake_input_from(scene), options);
}

std::string format_plan(const EffectPlan& p) {
  std::string s = "plan of " + (p.scene.empty() ? std::string("the scene") : p.scene) + " (preset " + p.preset + ")\n";
  const SceneFacts& f = p.facts;
  s += "  facts: " + plural(static_cast<std::size_t>(f.static_lights), "static light", "static lights") + ", " +
       plural(static_cast<std::size_t>(f.moving_lights), "moving light", "moving lights") + ", " +
       plural(static_cast<std::size_t>(f.static_meshes), "static mesh", "static meshes") + " (" +
       fixed(f.static_area_m2, 1) + " m^2, albedo " + fixed(f.static_albedo, 2) + "), " +
       plural(static_cast<std::size_t>(f.dynamic_meshes), "dynamic mesh", "dynamic meshes") + "\n";
  double seconds = 0.0;
  std::uint64_t bytes = 0;
  for (const PlannedEffect& e : p.effects) {
    const char* state = !e.enabled ? "off" : e.available ? "ON" : "NEEDED, NOT BUILT";
    char head[64];
    std::snprintf(head, sizeof head, "  %-13s %-4s", std::string(effect_key(e.method)).c_str(), state);
    s += std::string(head) + (e.enabled && !e.available ? " " : "  ") + e.reason + "\n";
    if (e.enabled && !e.available)
      s += "                      this build cannot bake " + std::string(effect_key(e.method)) +
           ": it will be skipped\n";
    if (e.enabled && !e.targets.empty()) s += "                      targets: " + list_names(e.targets, 6) + "\n";
    if (!e.estimate.basis.empty()) {
      s += "                      estimate: " + estimate_line(e.estimate.bake_seconds, e.estimate.runtime_bytes) + "\n";
      s += "                        from " + e.estimate.basis + "\n";
      seconds += e.estimate.bake_seconds;
      bytes += e.estimate.runtime_bytes;
    }
  }
  const std::vector<std::string> bake = p.methods_to_bake();
  s += "  bake: " + (bake.empty() ? std::string("nothing") : list_names(bake, 5)) +
       (bake.empty() ? "" : " (" + estimate_line(seconds, bytes) + ")") + "\n";
  for (const std::string& w : p.warnings) s += "  warning: " + w + "\n";
  return s;
}

}  // namespace gi
