// Basis radiance fields at run time: the dynamic objects' per-vertex indirect light (world
// probes + light interreflected between objects, GPU), and their bounce added into the
// static world's atlas; recomputed only on frames where an object moved or a light changed.

#include <chrono>

#include "brf/brf_io.h"
#include "brf/brf_lighting.h"
#include "brf/brf_mesh.h"
#include "brf/world_probes.h"
#include "prm/prm.h"
#include "system/method_table.h"
#include "system/prm_lighting.h"
#include "system/prm_probe_light.h"
#include "transport/static_scene.h"

namespace gi {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

class BrfMethod final : public MethodRuntime {
 public:
  BrfMethod(std::unique_ptr<BrfLighting> brf, std::unique_ptr<PrmProbeLight> probe)
      : brf_(std::move(brf)), probe_(std::move(probe)) {}

  void frame(FrameState& state) override {
    // The moving lights' first bounce in the world probes, re-projected only when the PRM's
    // entry irradiance changed.
    if (probe_ && state.moving_lights && probe_->update(*state.moving_lights) &&
        brf_->set_moving_world_light(probe_->radiance_sh())) {
      ++state.stats.prm_probe_updates;
      state.stats.last_prm_probe_ms = probe_->stats().last_ms;
    }
    state.objects_changed = brf_->update();
    if (state.objects_changed) {
      state.work = true;
      const BrfLighting::Stats& bs = brf_->stats();
      ++state.stats.brf_updates;
      state.stats.brf_moves = bs.objects_moved;
      state.stats.brf_pairs_evaluated = bs.pairs_evaluated;
      state.stats.brf_pairs_reused = bs.pairs_reused;
      state.stats.brf_pairs_culled = bs.pairs_culled;
      state.stats.brf_reach = bs.influence_scale;
      state.stats.last_brf_cpu_ms = bs.last_cpu_ms;
      state.stats.last_brf_gpu_ms = bs.last_gpu_ms;
    }
    if (!brf_->has_static_receivers() || state.atlas_texture == 0) return;
    const std::uint32_t out = atlas_target_like(state.atlas_texture, composite_);
    if (!composed_ || state.atlas_changed || state.objects_changed) {
      brf_->composite_world(state.atlas_texture, out);
      ++state.stats.world_composites;
      composed_ = true;
    }
    state.atlas_texture = out;
  }
  std::string label() const override { return "BRF"; }
  std::string disabled() const override { return brf_->stats().disabled; }
  engine::SsboHandle<engine::VertexIrradiance> vertex_irradiance_buffer(engine::Entity e) const override {
    return {brf_->vertex_buffer(e)};
  }
  engine::IndirectLightFrame::VertexRadianceLobes vertex_radiance_lobes(engine::Entity e) const override {
    return brf_->vertex_lobes(e);
  }

 private:
  std::unique_ptr<BrfLighting> brf_;
  std::unique_ptr<PrmProbeLight> probe_;  // the moving lights' first bounce in the world probes
  engine::GlTexture composite_;
  bool composed_ = false;
};

// The dynamic meshes' models and their instances, from the bundle's fields.
struct BrfModels {
  std::vector<BrfModel> models;
  std::vector<BrfInstance> instances;
  std::vector<engine::Entity> entities;  ///< Who draws each instance.
  std::vector<std::string> glossy;       ///< Meshes whose lobe the fields hold in separable terms.
};
engine::Result<BrfModels> read_models(const MethodLoad& load) {
  auto sources = dynamic_brf_meshes(load.input);
  if (!sources) return sources.error();
  auto loaded = load_brf(load.bundle_dir, *sources);
  if (!loaded) return loaded.error();
  BrfModels out;
  for (std::size_t i = 0; i < sources->size(); ++i) {
    const BrfSource& src = (*sources)[i];
    const auto model = static_cast<std::uint32_t>(out.models.size());
    const glm::vec3 albedo = brf_source_albedo(load.input, src);
    for (std::uint32_t k : src.instances) {
      out.instances.push_back({.model = model, .albedo = albedo, .specular = src.specular});
      out.entities.push_back(load.input.instances[k].entity);
    }
    if (loaded->meshes[i].model.glossy) out.glossy.push_back(src.name);
    out.models.push_back(std::move(loaded->meshes[i].model));
  }
  return out;
}

// The static world as the objects see it: the shared caster, the atlas texels they bounce
// light onto, and the PRM's entry points' surfaces (for the probes' moving light).
engine::Status link_static_world(MethodLoad& load, BrfWorldLink& world, std::vector<glm::vec3>& entry_albedo) {
  auto caster = load.static_world();
  if (load.layout == nullptr) {
    // Objects with no static atlas to bounce onto; with no static mesh at all, nothing shadows them.
    if (caster) world.caster = std::move(caster).value();
    return {};
  }
  if (!caster) return caster.error();
  auto s = prepare_static_scene(load.input, *load.layout, BakeLights::None, TexelPlacement::Raster,
                                std::move(caster).value());
  if (!s) return s.error();
  if (load.moving_lights) entry_albedo = prm_entry_albedo(*s, load.moving_lights->entry_points());
  world.atlas_width = s->texels.width;
  world.atlas_height = s->texels.height;
  for (std::size_t t = 0; t < s->texels.valid.size(); ++t)
    if (s->texels.valid[t] != 0) {
      world.receiver_texels.push_back(static_cast<std::uint32_t>(t));
      world.receiver_positions.push_back(s->texels.position[t]);
      world.receiver_normals.push_back(s->texels.normal[t]);
    }
  world.caster = std::move(s->caster);
  return {};
}

// The world probes: the light atlas's VPLs, plus (with a PRM) the moving lights' first bounce
// from its entry points (system/prm_probe_light.h). Without a light atlas the probes stand on
// the entry points alone (no static light).
engine::Result<std::unique_ptr<PrmProbeLight>> light_world_probes(MethodLoad& load, BrfWorldLink& world,
                                                                  std::vector<glm::vec3> entry_albedo) {
  const float spacing = load.settings.probe_spacing_m;
  if (load.atlas_bake && world.caster) {
    const auto t0 = std::chrono::steady_clock::now();
    auto probes =
        bake_world_probes(*world.caster, load.atlas_bake->vpls, load.atlas_bake->vpl_power, {.spacing_m = spacing});
    if (!probes) return probes.error();
    world.probes.emplace(std::move(probes).value());
    load.stats.load_probe_ms = static_cast<std::size_t>(ms_since(t0));
  }
  if (!load.moving_lights || !world.caster || entry_albedo.empty()) return std::unique_ptr<PrmProbeLight>();
  const auto t0 = std::chrono::steady_clock::now();
  const std::span<const PrmEntryPoint> entries = load.moving_lights->entry_points();
  if (!world.probes) {
    VplSet at_entries;
    for (const PrmEntryPoint& e : entries) {
      at_entries.position.push_back(e.position);
      at_entries.normal.push_back(e.normal);
      at_entries.area_m2.push_back(e.area_m2);
    }
    const std::vector<glm::vec3> dark(at_entries.position.size(), glm::vec3(0.0f));
    auto probes = bake_world_probes(*world.caster, at_entries, dark, {.spacing_m = spacing});
    if (!probes) return probes.error();
    world.probes.emplace(std::move(probes).value());
  }
  auto moving = PrmProbeLight::create(*world.caster, *world.probes, entries, std::move(entry_albedo));
  if (!moving) return moving.error();
  load.stats.load_probe_ms += static_cast<std::size_t>(ms_since(t0));
  return std::make_unique<PrmProbeLight>(std::move(moving).value());
}

}  // namespace

engine::Result<std::unique_ptr<MethodRuntime>> load_brf_method(MethodLoad& load) {
  auto models = read_models(load);
  if (!models) return models.error();
  BrfWorldLink world;
  std::vector<glm::vec3> entry_albedo;
  if (engine::Status s = link_static_world(load, world, entry_albedo); !s) return s.error();
  auto probe = light_world_probes(load, world, std::move(entry_albedo));
  if (!probe) return probe.error();
  const std::vector<std::string> glossy = std::move(models->glossy);
  const std::size_t receivers = world.receiver_texels.size();
  const std::size_t probe_count = world.probes ? world.probes->probe_count() : 0;
  const GISystemSettings& settings = load.settings;
  auto brf =
      BrfLighting::create(std::move(models->models), std::move(models->instances), std::move(models->entities),
                          load.scene.registry, std::move(world),
                          {.update = {.bounces = settings.brf_bounces, .cull_threshold = settings.brf_cull_threshold},
                           .phi_budget_bytes = settings.brf_pair_budget_bytes,
                           .log = settings.log});
  if (!brf) return brf.error();
  const auto& st = brf.value()->stats();
  load.stats.dynamic_objects = st.instances;
  load.stats.dynamic_vertices = st.vertices;
  load.stats.brf_field_bytes = st.field_bytes;
  load.text << "BRF: " << st.instances << " dynamic objects (" << st.vertices << " vertices, "
            << static_cast<double>(st.field_bytes) / 1e6 << " MB of basis + fields), " << settings.brf_bounces
            << " bounces; world light from " << probe_count << " probes; bounce onto " << receivers << " atlas texels";
  if (!glossy.empty()) {
    load.text << "; glossy:";
    for (std::size_t i = 0; i < glossy.size(); ++i) load.text << (i ? ", " : " ") << glossy[i];
  }
  load.text << '\n';
  if (*probe)
    load.text << "BRF world probes: + moving lights' first bounce from the PRM's entry points ("
              << (*probe)->stats().transfer_entries << " probe-entry links, "
              << static_cast<double>((*probe)->stats().transfer_bytes) / 1e6
              << " MB), re-projected when a moving light changes\n";
  return std::unique_ptr<MethodRuntime>(new BrfMethod(std::move(brf).value(), std::move(probe).value()));
}

}  // namespace gi
