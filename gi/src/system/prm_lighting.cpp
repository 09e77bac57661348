#include "system/prm_lighting.h"

#include <GL/glcorearb.h>
#include <engine/runtime_limits.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>
#include <unordered_map>

#include "bundle/light_signature.h"
#include "bundle/manifest.h"
#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
#include "prm/prm_io.h"
#include "prm/prm_runtime.h"
#include "raytrace/scene_adapter.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"
#include "uv/atlas_scene_writer.h"

namespace gi {

struct PrmLighting::Impl {
  const engine::Registry* registry = nullptr;
  std::vector<engine::AtlasMesh> atlas_meshes;  ///< The static meshes with TEXCOORD_1, for the renderer.
  Prm prm;
  std::vector<glm::vec3> base;              ///< Static-light atlas (empty: none).
  std::shared_ptr<const RayCaster> caster;  ///< The static world (shared with the other methods).
  std::unique_ptr<ThreadPool> pool;         ///< Traces the flux checks (settings.threads).
  PrmLightingSettings settings;
  std::optional<PrmGpuPass> pass;
  bool fresh = false;
  engine::IndirectLightFrame frame;
  Stats stats;

  // Per moving light: a fingerprint of everything that changes its light, and its entry
  // irradiance (eq. 4), kept while the fingerprint holds. Entry irradiance is linear in the
  // lights, so a frame where one of several moving lights changed recomputes that light only.
  struct LightCache {
    std::uint64_t signature = 0;
    std::vector<glm::vec3> entry;
    bool seen = false;
  };
  std::unordered_map<std::uint32_t, LightCache> lights;

  // Turns the PRM off for good (the renderer falls back to its stand-in), telling the host why.
  void disable(std::string reason) {
    stats.disabled = std::move(reason);
    prm.panes = {};
    pass.reset();
    frame.irradiance_atlas_texture = {};
    if (settings.log) settings.log(LogLevel::Warning, "PRM disabled: " + stats.disabled);
  }

  // Brings every moving light's cached entry irradiance up to date; returns whether any
  // changed (appeared, changed, or disappeared) and counts the recomputed ones.
  bool refresh_lights(std::size_t& recomputed) {
    bool changed = false;
    recomputed = 0;
    for (auto& [id, c] : lights) c.seen = false;
    registry->view<engine::Light, engine::WorldTransform>().each(
        [&](engine::Entity e, const engine::Light& l, const engine::WorldTransform& wt) {
          if (!l.moves) return;
          const std::uint64_t sig = light_signature(e, l, wt);
          LightCache& c = lights[e.id()];
          c.seen = true;
          if (!c.entry.empty() && c.signature == sig) return;
          c.signature = sig;
          changed = true;
          ++recomputed;
          // Off, or NaN / absurd at run time (GISystem warns once): no light.
          if (!l.enabled || engine::unusable_light(l, wt.matrix)) {
            c.entry.assign(prm.entries.size(), glm::vec3(0.0f));
            return;
          }
          const ReferenceLight ref = reference_light(l, wt.matrix);
          const std::vector<PointEmitter> emitters =
              light_point_emitters(std::span<const ReferenceLight>(&ref, 1), 16, prm.settings.seed);
          c.entry = entry_irradiance(prm, emitters, *caster, pool.get());
        });
    for (auto it = lights.begin(); it != lights.end();) {
      if (!it->second.seen) {
        it = lights.erase(it);
        changed = true;
      } else {
        ++it;
      }
    }
    return changed;
  }
};

PrmLighting::PrmLighting(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PrmLighting::~PrmLighting() = default;

engine::Result<std::unique_ptr<PrmLighting>> PrmLighting::from_bake(Prm prm, const LightAtlasBake* base,
                                                                    const engine::Scene& scene,
                                                                    PrmLightingSettings settings,
                                                                    std::shared_ptr<const RayCaster> static_world) {
  // The PRM's atlas (its panes' layout, or the atlas coarse panes are read at) is the light atlas's.
  if (base && (base->width != prm.atlas_width() || base->height != prm.atlas_height() ||
               base->layout.texels_per_metre != prm.atlas_layout().texels_per_metre))
    return engine::Error{scene.assets.source, "PRM",
                         "the light atlas (" + std::to_string(base->width) + "x" + std::to_string(base->height) +
                             ") and the PRM (" + std::to_string(prm.atlas_width()) + "x" +
                             std::to_string(prm.atlas_height()) +
                             ") were baked at different layouts; bake both at one density"};
  if (!static_world) {
    auto caster = make_static_caster(bake_input_from(scene));
    if (!caster) return caster.error();
    static_world = std::move(caster).value();
  }
  auto meshes = atlas_meshes_of(scene, prm.atlas_layout());
  if (!meshes) return meshes.error();
  auto impl = std::make_unique<Impl>();
  impl->atlas_meshes = std::move(meshes).value();
  impl->registry = &scene.registry;
  impl->prm = std::move(prm);
  if (base) impl->base = base->irradiance;
  impl->caster = std::move(static_world);
  impl->settings = settings;
  const unsigned threads =
      settings.threads > 0 ? settings.threads : std::min(4u, std::max(1u, std::thread::hardware_concurrency()));
  if (threads > 1) impl->pool = std::make_unique<ThreadPool>(threads);
  return std::unique_ptr<PrmLighting>(new PrmLighting(std::move(impl)));
}

std::span<const engine::AtlasMesh> PrmLighting::atlas_meshes() const { return impl_->atlas_meshes; }

const engine::IndirectLightFrame& PrmLighting::frame() {
  Impl& m = *impl_;
  ++m.stats.frames;
  if (!m.stats.disabled.empty()) return m.frame;
  if (!m.pass) {
    auto pass = PrmGpuPass::create(
        m.prm,
        {.encoding = m.settings.shared_exponent_panes ? PrmPaneEncoding::SharedExponent : PrmPaneEncoding::Half});
    if (!pass) {
      // No GL resources: leave the frame empty (the renderer falls back to its stand-in).
      m.disable(pass.error().to_string());
      return m.frame;
    }
    m.pass.emplace(std::move(pass).value());
    if (!m.base.empty()) (void)m.pass->set_base(m.base);
    m.frame.irradiance_atlas_texture = {m.pass->texture()};
    m.stats.gpu_bytes = m.pass->gpu_bytes();
    // The GPU holds the panes and the upsampler's taps now; nothing here reads the CPU copy
    // again (the weights need the entry points alone), and on Sponza's medium PRM the float
    // panes are 3x their RGB9E5 upload (docs/prm.md "What Sponza's medium PRM holds").
    m.prm.panes.values = {};
    m.prm.panes.block_value = {};
    if (m.prm.atlas) m.prm.atlas->upsampler.reset();
  }
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  std::size_t recomputed = 0;
  if (!m.refresh_lights(recomputed) && m.fresh) return m.frame;  // no moving light changed
  std::vector<glm::vec3> entry(m.prm.entries.size(), glm::vec3(0.0f));
  for (const auto& [id, c] : m.lights)
    for (std::size_t i = 0; i < entry.size() && i < c.entry.size(); ++i) entry[i] += c.entry[i];
  const std::vector<ClusterWeight> picked = select_clusters(cluster_weights(m.prm, entry), m.settings.active_clusters);
  m.stats.last_lights_recomputed = recomputed;
  m.stats.last_lights_reused = m.lights.size() - std::min(recomputed, m.lights.size());
  const auto t1 = Clock::now();
  if (engine::Status s = m.pass->run(picked); !s) {
    m.disable("update failed: " + s.error().to_string());
    return m.frame;
  }
  glFinish();
  const auto t2 = Clock::now();
  m.stats.last_weights_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  m.stats.last_gpu_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  m.stats.last_active_clusters = picked.size();
  ++m.stats.updates;
  m.fresh = true;
  return m.frame;
}

const char* PrmLighting::label() const { return impl_->base.empty() ? "PRM" : "light atlas + PRM"; }

const PrmLighting::Stats& PrmLighting::stats() const { return impl_->stats; }

std::span<const PrmEntryPoint> PrmLighting::entry_points() const { return impl_->prm.entries; }

const AtlasLayout& PrmLighting::layout() const { return impl_->prm.atlas_layout(); }

std::vector<glm::vec3> PrmLighting::moving_entry_irradiance() const {
  std::vector<glm::vec3> sum(impl_->prm.entries.size(), glm::vec3(0.0f));
  for (const auto& [id, c] : impl_->lights)
    for (std::size_t i = 0; i < sum.size() && i < c.entry.size(); ++i) sum[i] += c.entry[i];
  return sum;
}

}  // namespace gi
