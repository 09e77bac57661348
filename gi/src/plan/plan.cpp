// gi::plan: the rules of DESIGN.md §3 "Effects on demand" over a scene's facts (docs/plan.md).
#include <gi/plan.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <unordered_map>

#include "brf/brf_bake.h"
#include "plan/plan_cost.h"
#include "plan/static_surface_census.h"

namespace gi {

namespace {

constexpr std::string_view kKeys[kEffectMethodCount] = {"atlas", "prm", "dlm", "antiradiance", "brf"};
// What this build can bake (gi-bake --methods). DLM and antiradiance are not built yet.
constexpr bool kAvailable[kEffectMethodCount] = {true, true, false, false, true};

std::string name_of(const engine::Registry& reg, engine::Entity e) {
  const engine::Name* n = reg.try_get<engine::Name>(e);
  return n && !n->value.empty() ? n->value : "entity " + std::to_string(e.index);
}

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

struct EntityNodes {
  std::unordered_map<std::uint32_t, int> node_of;  // entity index -> node index
  int node(engine::Entity e) const {
    auto it = node_of.find(e.index);
    return it == node_of.end() ? -1 : it->second;
  }
};

// Why a light moves, or empty: its own flag, the plan options, or a dynamic node it hangs
// from (the light's own node or an ancestor, by mobility or DynamicTag).
std::string why_light_moves(const engine::Scene& scene, const EntityNodes& nodes, engine::Entity e,
                            const engine::Light& light, const std::string& name, const PlanOptions& options,
                            bool* only_by_node) {
  *only_by_node = false;
  if (light.moves) return "light_moves";
  if (std::find(options.moving_lights.begin(), options.moving_lights.end(), name) != options.moving_lights.end())
    return "scripted by the game";
  for (engine::Entity a = e; !a.is_null() && scene.registry.valid(a);) {
    const int n = nodes.node(a);
    const bool dynamic =
        scene.registry.has<engine::DynamicTag>(a) ||
        (n >= 0 && scene.assets.nodes[static_cast<std::size_t>(n)].gi.mobility == engine::Mobility::Dynamic);
    if (dynamic) {
      *only_by_node = true;
      return a == e ? "on a dynamic node" : "hangs from dynamic node '" + name_of(scene.registry, a) + "'";
    }
    const engine::Transform* t = scene.registry.try_get<engine::Transform>(a);
    a = t ? t->parent : engine::Entity{};
  }
  return {};
}

bool emissive(const engine::SceneAsset& assets, const engine::MeshRenderer& mr) {
  if (mr.mesh >= assets.meshes.size()) return false;
  for (const engine::Primitive& p : assets.meshes[mr.mesh].primitives) {
    const int mi = mr.material_override >= 0 ? mr.material_override : p.material;
    if (mi >= 0 && static_cast<std::size_t>(mi) < assets.materials.size() &&
        glm::length(assets.materials[static_cast<std::size_t>(mi)].emissive) > 0.0f)
      return true;
  }
  return false;
}

// The lowest roughness factor among the entity's materials (textures can only lower it
// further: glTF multiplies the factor by the texture), and that material's name.
std::pair<float, std::string> min_roughness(const engine::SceneAsset& assets, const engine::MeshRenderer& mr) {
  std::pair<float, std::string> best{2.0f, {}};
  if (mr.mesh >= assets.meshes.size()) return best;
  for (const engine::Primitive& p : assets.meshes[mr.mesh].primitives) {
    const int mi = mr.material_override >= 0 ? mr.material_override : p.material;
    const engine::Material def;
    const engine::Material& m = mi >= 0 && static_cast<std::size_t>(mi) < assets.materials.size()
                                    ? assets.materials[static_cast<std::size_t>(mi)]
                                    : def;
    if (m.roughness < best.first) best = {m.roughness, m.name};
  }
  return best;
}

std::string estimate_line(double seconds, std::uint64_t bytes) {
  return "~" + format_seconds(seconds) + " bake, ~" + format_bytes(bytes) + " at runtime";
}

}  // namespace

std::string_view effect_key(EffectMethod method) { return kKeys[static_cast<int>(method)]; }

std::optional<EffectMethod> effect_from_key(std::string_view key) {
  for (int i = 0; i < kEffectMethodCount; ++i)
    if (kKeys[i] == key) return static_cast<EffectMethod>(i);
  return std::nullopt;
}

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

EffectPlan plan(const engine::Scene& scene, const PlanOptions& options) {
  const engine::Registry& reg = scene.registry;
  EffectPlan out;
  out.scene = scene.assets.source;
  out.preset = options.preset;
  out.glossy_roughness = options.glossy_roughness;
  for (int i = 0; i < kEffectMethodCount; ++i) {
    PlannedEffect e;
    e.method = static_cast<EffectMethod>(i);
    e.available = kAvailable[i];
    out.effects.push_back(std::move(e));
  }
  auto& atlas = out.effects[0];
  auto& prm = out.effects[1];
  auto& dlm = out.effects[2];
  auto& anti = out.effects[3];
  auto& brf = out.effects[4];
  SceneFacts& facts = out.facts;

  EntityNodes nodes;
  for (std::size_t i = 0; i < scene.node_entities.size(); ++i)
    if (!scene.node_entities[i].is_null()) nodes.node_of[scene.node_entities[i].index] = static_cast<int>(i);

  // Lights.
  std::vector<std::string> static_lights, moving_lights, moving_why;
  LightPointCount points;
  reg.view<engine::Light>().each([&](engine::Entity e, const engine::Light& light) {
    if (!light.enabled) {
      ++facts.disabled_lights;
      return;
    }
    const std::string name = name_of(reg, e);
    bool only_by_node = false;
    const std::string why = why_light_moves(scene, nodes, e, light, name, options, &only_by_node);
    if (!why.empty()) {
      moving_lights.push_back(name);
      moving_why.push_back(why);
      if (only_by_node)
        out.warnings.push_back("light '" + name + "' " + why +
                               " but is not flagged light_moves: the light atlas would bake it "
                               "as static; set gi.light_moves");
      return;
    }
    static_lights.push_back(name);
    if (light.type == engine::LightType::Area)
      ++points.sampled;
    else if (light.type == engine::LightType::Directional)
      ++points.directional;
    else
      ++points.punctual;
  });
  facts.static_lights = static_cast<int>(static_lights.size());
  facts.moving_lights = static_cast<int>(moving_lights.size());

  // Meshes.
  std::vector<std::string> static_meshes, emissive_meshes, glossy, glossy_why, deforming;
  std::map<std::uint32_t, std::vector<std::string>> dynamic_by_mesh;  // mesh -> entities
  reg.view<engine::MeshRenderer>().each([&](engine::Entity e, const engine::MeshRenderer& mr) {
    const std::string name = name_of(reg, e);
    // Deforming regions: the flagged node and every mesh below it.
    for (engine::Entity a = e; !a.is_null() && reg.valid(a);) {
      const int n = nodes.node(a);
      if (n >= 0 && scene.assets.nodes[static_cast<std::size_t>(n)].gi.region == engine::GiRegion::Deforming) {
        deforming.push_back(name);
        break;
      }
      const engine::Transform* t = reg.try_get<engine::Transform>(a);
      a = t ? t->parent : engine::Entity{};
    }
    if (reg.has<engine::DynamicTag>(e)) {
      ++facts.dynamic_meshes;
      dynamic_by_mesh[mr.mesh].push_back(name);
      return;
    }
    ++facts.static_meshes;
    static_meshes.push_back(name);
    if (emissive(scene.assets, mr)) emissive_meshes.push_back(name);
    const auto [roughness, material] = min_roughness(scene.assets, mr);
    if (roughness < options.glossy_roughness) {
      glossy.push_back(name);
      glossy_why.push_back("'" + name + "' (" + material + ") has roughness " + fixed(roughness, 2));
    }
  });
  facts.emissive_surfaces = static_cast<int>(emissive_meshes.size());
  points.sampled += 2 * facts.emissive_surfaces;  // emissive quads: two triangles each, typically

  const StaticSurfaceCensus census = census_static_surfaces(scene);
  facts.static_area_m2 = census.area_m2;
  facts.static_albedo = census.albedo;

  // Presets (the bakers' own), with gi-bake's overrides.
  auto atlas_settings = light_atlas_preset(options.preset);
  auto prm_settings = prm_preset(options.preset);
  const bool estimates = atlas_settings && prm_settings;
  if (!estimates)
    out.warnings.push_back("unknown preset '" + options.preset + "' (preview, medium, high): no estimates");
  if (estimates) {
    if (options.texels_per_metre > 0.0f)
      atlas_settings->texels_per_metre = prm_settings->texels_per_metre = options.texels_per_metre;
    if (options.vpls > 0) atlas_settings->vpl_count = options.vpls;
    if (options.samples_per_vpl > 0) atlas_settings->samples_per_vpl = options.samples_per_vpl;
    if (options.bounces > 0) atlas_settings->bounces = options.bounces;
  }

  const bool any_light = !static_lights.empty() || !moving_lights.empty() || !emissive_meshes.empty();
  if (!any_light) {
    const std::string why =
        facts.disabled_lights > 0
            ? "no light is on (" + plural(static_cast<std::size_t>(facts.disabled_lights), "light is", "lights are") +
                  " switched off) and no surface is emissive: nothing to bake"
            : "the scene has no light and no emissive surface: nothing to bake";
    for (PlannedEffect& e : out.effects) e.reason = why;
    return out;
  }

  // Light atlas: static light sources on static geometry.
  const std::size_t static_sources = static_lights.size() + emissive_meshes.size();
  if (static_sources > 0 && !static_meshes.empty()) {
    atlas.enabled = true;
    const std::string area = fixed(census.area_m2, 1) + " m^2";
    const std::string meshes = plural(static_meshes.size(), "static mesh", "static meshes");
    const std::string emitting = plural(emissive_meshes.size(), "emissive surface", "emissive surfaces");
    if (static_lights.empty()) {
      atlas.reason = emitting + (emissive_meshes.size() == 1 ? " lights " : " light ") + meshes + " (" + area + ")";
    } else {
      atlas.reason = plural(static_lights.size(), "static light", "static lights") +
                     (static_lights.size() == 1 ? " lights " : " light ") + meshes + " (" + area +
                     (emissive_meshes.empty() ? "" : "; " + emitting + " too") + ")";
    }
    atlas.targets = static_meshes;
    if (estimates) {
      const BakeWork w = light_atlas_work(census, *atlas_settings, points);
      const AtlasTexelEstimate t = atlas_texels(census, atlas_settings->texels_per_metre);
      atlas.estimate = {w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(t.lit_texels),
                        fixed(census.area_m2, 1) + " m^2 x " + fixed(atlas_settings->texels_per_metre, 0) +
                            "^2 texels/m^2 -> ~" + std::to_string(static_cast<long long>(t.lit_texels)) +
                            " texels (atlas " + std::to_string(t.width) + "x" + std::to_string(t.height) + ") x " +
                            std::to_string(atlas_settings->vpl_count) + " VPLs, " +
                            std::to_string(atlas_settings->bounces) + " bounces"};
    }
  } else if (static_meshes.empty()) {
    atlas.reason = "no static mesh: nothing for a light atlas to hold";
  } else {
    atlas.reason =
        "no static light (" + plural(moving_lights.size(), "light moves", "lights move") + ") -> no light atlas";
  }

  // PRM: moving lights over static geometry.
  if (!moving_lights.empty() && !static_meshes.empty()) {
    prm.enabled = true;
    std::vector<std::string> parts;
    for (std::size_t i = 0; i < moving_lights.size() && i < 3; ++i)
      parts.push_back("light '" + moving_lights[i] + "' moves (" + moving_why[i] + ")");
    prm.reason =
        list_names(parts, 3) + " -> PRM panes over " + plural(static_meshes.size(), "static mesh", "static meshes");
    prm.targets = static_meshes;
    if (estimates) {
      double nodes_est = 0.0;
      const BakeWork w = prm_work(census, *prm_settings, &nodes_est);
      const AtlasTexelEstimate t = atlas_texels(census, prm_settings->texels_per_metre);
      prm.estimate = {w.bake_seconds, w.runtime_bytes, static_cast<std::uint64_t>(nodes_est),
                      std::to_string(prm_settings->entry_points) + " entry points x N_s " +
                          fixed(prm_settings->splitting, 0) + " at albedo " + fixed(census.albedo, 2) + " -> ~" +
                          std::to_string(static_cast<long long>(nodes_est)) + " path nodes x ~" +
                          std::to_string(static_cast<long long>(t.pane_texels)) + " pane texels; " +
                          std::to_string(prm_settings->clusters) + " panes as half floats"};
    }
  } else if (moving_lights.empty()) {
    prm.reason = "no light moves -> no PRM panes";
  } else {
    prm.reason = "lights move but there is no static mesh to relight";
  }

  // Directional light maps: glossy static surfaces.
  const std::string threshold = fixed(options.glossy_roughness, 2);
  if (!glossy.empty()) {
    dlm.enabled = true;
    dlm.reason = "static surface " + list_names(glossy_why, 2) + " < " + threshold + " -> directional light maps";
    dlm.targets = glossy;
  } else {
    dlm.reason = "no static surface has roughness < " + threshold + " -> no directional maps";
  }

  // Antiradiance: flagged deforming or opening regions.
  if (!deforming.empty()) {
    anti.enabled = true;
    anti.reason = plural(deforming.size(), "mesh is", "meshes are") + " flagged gi.region \"deforming\" (" +
                  quoted_list(deforming) + ") -> antiradiance for that region";
    anti.targets = deforming;
  } else {
    anti.reason = "no node is flagged gi.region \"deforming\" -> no antiradiance";
  }

  // Basis radiance fields: the meshes of dynamic entities, once per mesh.
  if (!dynamic_by_mesh.empty()) {
    brf.enabled = true;
    std::vector<std::string> mesh_names, glossy_meshes;
    std::size_t vertices = 0, triangles = 0;
    BakeWork total;
    const auto brf_settings = brf_preset(options.preset);
    const PcaBasisSettings basis = brf_settings ? brf_settings->basis : PcaBasisSettings{};
    const RadianceFieldSettings field = brf_settings ? brf_settings->field : RadianceFieldSettings{};
    for (const auto& [mesh, users] : dynamic_by_mesh) {
      if (mesh >= scene.assets.meshes.size()) continue;
      const engine::Mesh& m = scene.assets.meshes[mesh];
      mesh_names.push_back(m.name.empty() ? "mesh " + std::to_string(mesh) : m.name);
      std::size_t v = 0, t = 0;
      for (const engine::Primitive& p : m.primitives) v += p.positions.size(), t += p.indices.size() / 3;
      vertices += v, triangles += t;
      // A glossy material (brf_glossy_lobe) multiplies the field by 1 + its terms; the
      // separation may keep one more term to keep an azimuthal pair whole.
      const int material = m.primitives.empty() ? -1 : m.primitives.front().material;
      const bool is_glossy = material >= 0 && static_cast<std::size_t>(material) < scene.assets.materials.size() &&
                          brf_glossy_lobe(scene.assets.materials[static_cast<std::size_t>(material)]).has_value();
      const int terms = is_glossy ? 2 + (brf_settings ? brf_settings->glossy.terms : 4) : 1;
      if (is_glossy) glossy_meshes.push_back(mesh_names.back());
      const BakeWork w = brf_work(v, t, basis, field, terms);
      total.bake_seconds += w.bake_seconds;
      total.runtime_bytes += w.runtime_bytes;
      total.units += w.units;
    }
    brf.reason =
        plural(static_cast<std::size_t>(facts.dynamic_meshes), "dynamic entity uses ", "dynamic entities use ") +
        plural(mesh_names.size(), "mesh", "meshes") + " (" + list_names(mesh_names) +
        ") -> a basis and a field per mesh" +
        (glossy_meshes.empty() ? std::string()
                               : "; glossy metal (" + list_names(glossy_meshes) + ") -> its lobe in separable terms");
    brf.targets = mesh_names;
    brf.estimate = {total.bake_seconds, total.runtime_bytes, static_cast<std::uint64_t>(total.units),
                    std::to_string(mesh_names.size()) + " meshes, " + std::to_string(vertices) +
                        " vertices; per mesh " + std::to_string(field.spheres) + " spheres x 6 x " +
                        std::to_string(field.face_resolution) + "^2 points x " + std::to_string(basis.basis) +
                        " functions x " + std::to_string(field.sh_bands * field.sh_bands) +
                        " SH coefficients x 4 B, " + std::to_string(field.directions) + " rays per point (brf_preset)"};
  } else {
    brf.reason = "no dynamic mesh -> no basis radiance fields";
  }

  for (PlannedEffect& e : out.effects)
    if (!e.enabled || !e.available) e.estimate = {};
  return out;
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
