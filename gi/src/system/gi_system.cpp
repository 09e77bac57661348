#include <GL/glcorearb.h>
#include <engine/components.h>
#include <engine/gpu/gl_objects.h>
#include <engine/runtime_limits.h>
#include <gi/gi_system.h>
#include <gi/plan.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <sstream>
#include <unordered_set>

#include "antiradiance/antiradiance_io.h"
#include "brf/brf_io.h"
#include "brf/brf_lighting.h"
#include "brf/brf_mesh.h"
#include "brf/world_probes.h"
#include "bundle/manifest.h"
#include "dlm/dlm_io.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "prm/prm.h"
#include "prm/prm_io.h"
#include "system/antiradiance_lighting.h"
#include "system/dlm_lighting.h"
#include "system/light_atlas_lighting.h"
#include "system/prm_lighting.h"
#include "system/prm_probe_light.h"
#include "system/sky_visibility.h"
#include "transport/static_scene.h"

namespace gi {

namespace {

// The frame handed to the renderer: the atlas texture plus the dynamic objects' buffers.
struct SystemFrame final : engine::IndirectLightFrame {
  const BrfLighting* brf = nullptr;
  std::uint32_t vertex_irradiance_buffer(engine::Entity e) const override { return brf ? brf->vertex_buffer(e) : 0; }
  // A glossy dynamic object's view-dependent indirect light (BRF glossy terms).
  VertexRadianceLobes vertex_radiance_lobes(engine::Entity e) const override {
    return brf ? brf->vertex_lobes(e) : VertexRadianceLobes{};
  }
  // The sky's occlusion on dynamic entities (system/sky_visibility.h), under a sky only.
  const SkyVisibility* sky = nullptr;
  bool sky_visibility(engine::Entity e, float (&axes)[6]) const override { return sky && sky->get(e, axes); }
};

}  // namespace

struct GISystem::Impl {
  std::unique_ptr<LightAtlasLighting> atlas;
  std::unique_ptr<PrmLighting> prm;
  std::unique_ptr<BrfLighting> brf;
  std::unique_ptr<PrmProbeLight> prm_probe;  // the moving lights' first bounce in the BRF world probes
  std::unique_ptr<DlmLighting> dlm;          // directional light maps of the glossy static surfaces
  std::unique_ptr<AntiradianceLighting> anti;
  std::unique_ptr<SkyVisibility> sky;  // dynamic entities' sky occlusion, when the scene has a sky
  engine::GlTexture anti_out;
  bool anti_composed = false;
  bool anti_disabled = false;
  engine::GlTexture composite;
  int width = 0, height = 0;
  std::uint64_t seen_prm_updates = 0;
  bool composed = false;
  SystemFrame frame;
  Stats stats;
  std::string label;
  std::string description;
  bool prm_disabled = false;
  bool brf_disabled = false;
  const engine::Registry* registry = nullptr;
  LogCallback log;
  std::unordered_set<std::uint32_t> warned;  // entities skipped and told, while they stay unusable

  // Lights and dynamic objects the providers leave out this frame (engine/runtime_limits.h):
  // counted, and each told once when it starts being skipped.
  void check_runtime_inputs() {
    std::unordered_set<std::uint32_t> now;
    const auto skip = [&](engine::Entity e, const char* what, const char* why) {
      now.insert(e.id());
      if (warned.contains(e.id()) || !log) return;
      const auto* name = registry->try_get<engine::Name>(e);
      log(LogLevel::Warning, std::string("GI: ") + what + " '" +
                                 (name ? name->value : "entity " + std::to_string(e.id())) + "' skipped: " + why);
    };
    registry->view<engine::Light, engine::WorldTransform>().each(
        [&](engine::Entity e, const engine::Light& l, const engine::WorldTransform& wt) {
          if (!l.enabled) return;
          if (const char* why = engine::unusable_light(l, wt.matrix)) skip(e, "light", why);
        });
    registry->view<engine::DynamicTag, engine::WorldTransform>().each(
        [&](engine::Entity e, const engine::DynamicTag&, const engine::WorldTransform& wt) {
          if (const char* why = engine::unusable_world_matrix(wt.matrix)) skip(e, "dynamic object", why);
        });
    stats.skipped_entities = now.size();
    warned = std::move(now);
  }

  // What runs: the PRM (or the plain atlas) and the BRF, less what turned off.
  void relabel() {
    label = prm && !prm_disabled ? prm->label() : atlas ? atlas->label() : "";
    if (brf && !brf_disabled) label += label.empty() ? "BRF" : " + BRF";
    if (dlm) label += " + DLM";
    if (anti && !anti_disabled) label += label.empty() ? "antiradiance" : " + antiradiance";
  }
  // The providers have told the host through the log already; the stats keep it.
  void turned_off(const char* method, const std::string& reason) {
    stats.disabled.push_back(std::string(method) + ": " + reason);
  }
};

GISystem::GISystem(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GISystem::~GISystem() = default;

engine::Result<std::unique_ptr<GISystem>> GISystem::load(const std::filesystem::path& bundle_dir, engine::Scene& scene,
                                                         GISystemSettings settings) {
  auto manifest = read_manifest(bundle_dir);
  if (!manifest) return manifest.error();
  const bool has_atlas = manifest->methods.contains("light_atlas");
  const bool has_prm = manifest->methods.contains("prm");
  const bool has_brf = manifest->methods.contains("brf");
  const bool has_dlm = manifest->methods.contains(kDlmMethod);
  const bool has_anti = manifest->methods.contains(kAntiradianceMethod);
  if (!has_atlas && !has_prm && !has_brf && !has_dlm)
    return engine::Error{(bundle_dir / "manifest.json").string(), "methods",
                         "the bundle holds no light atlas, PRM, basis radiance fields or directional light maps"};
  auto impl = std::make_unique<Impl>();
  std::ostringstream text;
  // The scene as the bakers saw it: hashes, layouts and BRF sources are checked against it.
  const BakeInput input = bake_input_from(scene);
  // What the scene calls for (gi::plan) next to what the bundle holds.
  const EffectPlan wanted = plan(input, {});
  const auto in_bundle = [&](EffectMethod m) {
    switch (m) {
      case EffectMethod::LightAtlas:
        return has_atlas;
      case EffectMethod::Prm:
        return has_prm;
      case EffectMethod::BasisRadianceFields:
        return has_brf;
      case EffectMethod::DirectionalLightMaps:
        return has_dlm;
      case EffectMethod::Antiradiance:
        return has_anti;
      default:
        return false;
    }
  };
  for (const PlannedEffect& e : wanted.effects) {
    text << "plan " << effect_key(e.method) << ": "
         << (!e.enabled            ? "off"
             : !e.available        ? "needed, not built"
             : in_bundle(e.method) ? "on"
                                   : "needed, NOT IN THE BUNDLE (re-bake)")
         << " - " << e.reason << '\n';
  }

  std::optional<LightAtlasBake> atlas;
  if (has_atlas) {
    auto a = load_light_atlas(bundle_dir, input);
    if (!a) return a.error();
    atlas.emplace(std::move(a).value());
    text << "light atlas: " << atlas->width << "x" << atlas->height << ", static lights, " << atlas->settings.bounces
         << " bounces\n";
  }
  std::optional<Prm> prm;
  if (has_prm) {
    auto p = load_prm(bundle_dir, input);
    if (!p) return p.error();
    prm.emplace(std::move(p).value());
    text << "PRM: " << prm->cluster_count << " clusters, K = " << settings.prm_active_clusters
         << ", relit when a moving light changes\n";
  }

  // Directional light maps: drawn at the uv1 of the light atlas's (or PRM's) layout.
  if (has_dlm) {
    auto d = load_dlm(bundle_dir, input);
    if (!d) return d.error();
    const int w = atlas ? atlas->width : prm ? prm->width : 0;
    const int h = atlas ? atlas->height : prm ? prm->height : 0;
    if (w == 0)
      return engine::Error{(bundle_dir / kDlmFile).string(), "",
                           "directional light maps need the light atlas's (or PRM's) uv1 layout, and the bundle has "
                           "neither (bake atlas too)"};
    const int directions = static_cast<int>(d->directions.size());
    const std::size_t glossy = d->stats.glossy_texels;
    auto l = DlmLighting::from_bake(std::move(d).value(), w, h);
    if (!l) {
      engine::Error e = l.error();
      e.file = (bundle_dir / kDlmFile).string();
      return e;
    }
    impl->dlm = std::move(l).value();
    impl->stats.dlm_texels = impl->dlm->texels();
    impl->stats.dlm_gpu_bytes = impl->dlm->gpu_bytes();
    text << "DLM: " << directions << " directions x " << impl->dlm->texels() << " texels (" << glossy
         << " on glossy static surfaces, " << static_cast<double>(impl->dlm->gpu_bytes()) / 1e6
         << " MB on the GPU); specular lobe vs the view, per pixel\n";
  }

  // Basis radiance fields, coupled to the static world before the static meshes get uv1
  // (the atlas texels are those of the layout built from the original meshes).
  if (has_brf) {
    auto sources = dynamic_brf_meshes(input);
    if (!sources) return sources.error();
    auto loaded = load_brf(bundle_dir, *sources);
    if (!loaded) return loaded.error();
    std::vector<BrfModelData> models;
    std::vector<BrfInstanceBinding> bindings;
    for (std::size_t i = 0; i < sources->size(); ++i) {
      BrfSource& src = (*sources)[i];
      BrfMeshBake& b = loaded->meshes[i];
      const auto model = static_cast<std::uint32_t>(models.size());
      const glm::vec3 albedo = brf_source_albedo(input, src);
      for (std::uint32_t k : src.instances)
        bindings.push_back({input.instances[k].entity, model, albedo, src.specular});
      models.push_back({src.name, std::move(src.mesh), std::move(b.basis), std::move(b.field), std::move(b.glossy)});
    }
    BrfWorldLink world;
    const AtlasLayout* layout = atlas ? &atlas->layout : prm ? &prm->layout : nullptr;
    std::vector<glm::vec3> entry_albedo;  // the PRM's entry points' surfaces, for the probes' moving light
    if (layout != nullptr) {
      auto s = prepare_static_scene(input, *layout, BakeLights::None);
      if (!s) return s.error();
      if (prm) entry_albedo = prm_entry_albedo(*s, prm->entries);
      world.atlas_width = s->texels.width;
      world.atlas_height = s->texels.height;
      for (std::size_t t = 0; t < s->texels.valid.size(); ++t)
        if (s->texels.valid[t] != 0) {
          world.receiver_texels.push_back(static_cast<std::uint32_t>(t));
          world.receiver_positions.push_back(s->texels.position[t]);
          world.receiver_normals.push_back(s->texels.normal[t]);
        }
      world.caster = std::move(s->caster);
    } else if (auto c = make_static_caster(input)) {
      world.caster = std::move(c).value();
    }
    if (atlas && world.caster) {
      const auto t0 = std::chrono::steady_clock::now();
      auto probes =
          bake_world_probes(*world.caster, atlas->vpls, atlas->vpl_power, {.spacing_m = settings.probe_spacing_m});
      if (!probes) return probes.error();
      world.probes.emplace(std::move(probes).value());
      impl->stats.load_probe_ms = static_cast<std::size_t>(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    // The moving lights' first bounce in the probes: the PRM's entry points as emitters
    // (system/prm_probe_light.h). Without a light atlas the probes stand on the entry points
    // alone (no static light).
    if (prm && world.caster && !entry_albedo.empty()) {
      const auto t0 = std::chrono::steady_clock::now();
      if (!world.probes) {
        VplSet at_entries;
        for (const PrmEntryPoint& e : prm->entries) {
          at_entries.position.push_back(e.position);
          at_entries.normal.push_back(e.normal);
          at_entries.area_m2.push_back(e.area_m2);
        }
        const std::vector<glm::vec3> dark(at_entries.position.size(), glm::vec3(0.0f));
        auto probes = bake_world_probes(*world.caster, at_entries, dark, {.spacing_m = settings.probe_spacing_m});
        if (!probes) return probes.error();
        world.probes.emplace(std::move(probes).value());
      }
      auto moving = PrmProbeLight::create(*world.caster, *world.probes, prm->entries, std::move(entry_albedo));
      if (!moving) return moving.error();
      impl->prm_probe = std::make_unique<PrmProbeLight>(std::move(moving).value());
      impl->stats.load_probe_ms += static_cast<std::size_t>(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    const std::size_t receivers = world.receiver_texels.size();
    const std::size_t probe_count = world.probes ? world.probes->probe_count() : 0;
    auto brf =
        BrfLighting::create(std::move(models), std::move(bindings), scene.registry, std::move(world),
                            {.update = {.bounces = settings.brf_bounces, .cull_threshold = settings.brf_cull_threshold},
                             .log = settings.log});
    if (!brf) return brf.error();
    impl->brf = std::move(brf).value();
    const auto& st = impl->brf->stats();
    impl->stats.dynamic_objects = st.instances;
    impl->stats.dynamic_vertices = st.vertices;
    impl->stats.brf_field_bytes = st.field_bytes;
    text << "BRF: " << st.instances << " dynamic objects (" << st.vertices << " vertices, "
         << static_cast<double>(st.field_bytes) / 1e6 << " MB of basis + fields), " << settings.brf_bounces
         << " bounces; world light from " << probe_count << " probes; bounce onto " << receivers << " atlas texels\n";
    if (impl->prm_probe)
      text << "BRF world probes: + moving lights' first bounce from the PRM's entry points ("
           << impl->prm_probe->stats().transfer_entries << " probe-entry links, "
           << static_cast<double>(impl->prm_probe->stats().transfer_bytes) / 1e6
           << " MB), re-projected when a moving light changes\n";
  }

  // Antiradiance: the deforming region's change, added into the atlas of the same layout.
  if (has_anti) {
    const AtlasLayout* layout = atlas ? &atlas->layout : prm ? &prm->layout : nullptr;
    if (layout == nullptr)
      return engine::Error{(bundle_dir / "manifest.json").string(), "methods.antiradiance",
                           "antiradiance adds into the light atlas: the bundle needs a light atlas or a PRM too"};
    auto bake = load_antiradiance(bundle_dir, input);
    if (!bake) return bake.error();
    auto anti = AntiradianceLighting::create(std::move(bake).value(), input, *layout, scene.registry);
    if (!anti) return anti.error();
    impl->anti = std::move(anti).value();
    const auto& st = impl->anti->stats();
    text << "antiradiance: " << st.elements << " elements, " << st.links << " links, " << st.covered_texels
         << " atlas texels; solved on frames where a deforming node moves\n";
  }

  if (prm) {
    auto p = PrmLighting::from_bake(std::move(*prm), atlas ? &*atlas : nullptr, scene,
                                    {.active_clusters = settings.prm_active_clusters,
                                     .log = settings.log,
                                     .shared_exponent_panes = settings.prm_shared_exponent_panes});
    if (!p) return p.error();
    impl->prm = std::move(p).value();
  } else if (atlas) {
    auto a = LightAtlasLighting::from_bake(*atlas, scene);
    if (!a) return a.error();
    impl->atlas = std::move(a).value();
  }
  // The atlas (alone or under the PRM's panes) holds the sky's direct light, and every static
  // light's with include_direct: the renderer draws neither again on the static world.
  impl->frame.atlas_holds_sky = atlas.has_value();
  impl->frame.atlas_holds_static_lights = atlas.has_value() && atlas->settings.include_direct;
  impl->registry = &scene.registry;
  impl->log = settings.log;
  impl->relabel();
  impl->description = text.str();
  impl->frame.brf = impl->brf.get();
  if (engine::sky_lit(scene.assets.environment.sky_radiance, scene.assets.environment.sky_gradient)) {
    auto sky = SkyVisibility::create(scene);  // the renderer's sky term on dynamic entities
    if (!sky) return sky.error();
    impl->sky = std::move(sky).value();
    impl->frame.sky = impl->sky.get();
  }
  return std::unique_ptr<GISystem>(new GISystem(std::move(impl)));
}

const engine::IndirectLightFrame& GISystem::frame() {
  Impl& m = *impl_;
  ++m.stats.frames;
  m.check_runtime_inputs();
  bool work = false;
  std::uint32_t base = 0;
  bool base_changed = false;
  if (m.prm) {
    base = m.prm->frame().irradiance_atlas_texture;
    const PrmLighting::Stats& ps = m.prm->stats();
    if (!ps.disabled.empty() && !m.prm_disabled) {
      m.prm_disabled = true;
      m.turned_off("PRM", ps.disabled);
      m.relabel();
    }
    if (ps.updates != m.seen_prm_updates) {
      m.seen_prm_updates = ps.updates;
      ++m.stats.prm_updates;
      m.stats.last_prm_ms = ps.last_weights_ms + ps.last_gpu_ms;
      base_changed = true;
      work = true;
    }
    // The moving lights' first bounce in the BRF world probes, re-projected only when the PRM's
    // entry irradiance changed.
    if (m.prm_probe && m.brf && m.prm_probe->update(*m.prm) &&
        m.brf->set_moving_world_light(m.prm_probe->radiance_sh())) {
      ++m.stats.prm_probe_updates;
      m.stats.last_prm_probe_ms = m.prm_probe->stats().last_ms;
    }
  } else if (m.atlas) {
    base = m.atlas->frame().irradiance_atlas_texture;
    base_changed = !m.composed;
  }
  bool objects_changed = false;
  if (m.brf) {
    objects_changed = m.brf->update();
    if (!m.brf->stats().disabled.empty() && !m.brf_disabled) {
      m.brf_disabled = true;
      m.turned_off("BRF", m.brf->stats().disabled);
      m.relabel();
    }
    if (objects_changed) {
      work = true;
      const BrfLighting::Stats& bs = m.brf->stats();
      ++m.stats.brf_updates;
      m.stats.brf_moves = bs.objects_moved;
      m.stats.brf_pairs_evaluated = bs.pairs_evaluated;
      m.stats.brf_pairs_reused = bs.pairs_reused;
      m.stats.brf_pairs_culled = bs.pairs_culled;
      m.stats.last_brf_cpu_ms = bs.last_cpu_ms;
      m.stats.last_brf_gpu_ms = bs.last_gpu_ms;
    }
  }
  m.frame.irradiance_atlas_texture = base;
  if (m.brf && m.brf->has_static_receivers() && base != 0) {
    if (m.composite.empty()) {
      GLint w = 0, h = 0;
      glGetTextureLevelParameteriv(base, 0, GL_TEXTURE_WIDTH, &w);
      glGetTextureLevelParameteriv(base, 0, GL_TEXTURE_HEIGHT, &h);
      m.composite = engine::GlTexture::create_2d(GL_RGBA32F, w, h);
      glTextureParameteri(m.composite.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(m.composite.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTextureParameteri(m.composite.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(m.composite.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    if (!m.composed || base_changed || objects_changed) {
      m.brf->composite_world(base, m.composite.id());
      ++m.stats.world_composites;
      m.composed = true;
    }
    m.frame.irradiance_atlas_texture = m.composite.id();
  }
  if (m.anti && !m.anti_disabled && m.frame.irradiance_atlas_texture != 0) {
    const bool moved = m.anti->update();
    if (!m.anti->disabled().empty()) {
      m.anti_disabled = true;
      m.turned_off("antiradiance", m.anti->disabled());
      m.relabel();
    } else {
      const std::uint32_t src = m.frame.irradiance_atlas_texture;
      if (m.anti_out.empty()) {
        GLint w = 0, h = 0;
        glGetTextureLevelParameteriv(src, 0, GL_TEXTURE_WIDTH, &w);
        glGetTextureLevelParameteriv(src, 0, GL_TEXTURE_HEIGHT, &h);
        m.anti_out = engine::GlTexture::create_2d(GL_RGBA32F, w, h);
        glTextureParameteri(m.anti_out.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(m.anti_out.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(m.anti_out.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(m.anti_out.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      }
      if (moved || base_changed || objects_changed || !m.anti_composed) {
        m.anti->composite(src, m.anti_out.id());
        m.anti_composed = true;
      }
      m.frame.irradiance_atlas_texture = m.anti_out.id();
      if (moved) {
        work = true;
        ++m.stats.antiradiance_updates;
        m.stats.antiradiance_relinked_elements = m.anti->stats().relinked_elements;
        m.stats.last_antiradiance_ms = m.anti->stats().last_ms;
      }
    }
  }
  m.composed = true;
  if (m.sky) m.sky->update();
  if (m.dlm) m.dlm->fill(m.frame);
  if (!work) ++m.stats.idle_frames;
  return m.frame;
}

const char* GISystem::label() const { return impl_->label.c_str(); }
const GISystem::Stats& GISystem::stats() const { return impl_->stats; }
std::string GISystem::describe() const { return impl_->description; }

}  // namespace gi
