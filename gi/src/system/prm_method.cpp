// Precomputed radiance maps at run time: the moving lights' indirect light, re-summed on the
// GPU on frames where a moving light changed, over the light atlas's static light (which it
// supersedes: one texture holds both).

#include "prm/prm.h"
#include "prm/prm_io.h"
#include "system/method_table.h"
#include "system/prm_lighting.h"

namespace gi {

namespace {

class PrmMethod final : public MethodRuntime {
 public:
  explicit PrmMethod(std::unique_ptr<PrmLighting> lighting) : lighting_(std::move(lighting)) {}
  void frame(FrameState& state) override {
    state.atlas_texture = lighting_->frame().irradiance_atlas_texture.gl_name;
    state.moving_lights = lighting_.get();
    const PrmLighting::Stats& ps = lighting_->stats();
    if (ps.updates != seen_updates_) {
      seen_updates_ = ps.updates;
      ++state.stats.prm_updates;
      state.stats.last_prm_ms = ps.last_weights_ms + ps.last_gpu_ms;
      state.atlas_changed = true;
      state.work = true;
    }
  }
  std::string label() const override { return lighting_->label(); }
  std::span<const engine::AtlasMesh> atlas_meshes() const override { return lighting_->atlas_meshes(); }
  std::string disabled() const override { return lighting_->stats().disabled; }

 private:
  std::unique_ptr<PrmLighting> lighting_;
  std::uint64_t seen_updates_ = 0;
};

}  // namespace

engine::Result<std::unique_ptr<MethodRuntime>> load_prm_method(MethodLoad& load) {
  auto p = load_prm(load.bundle_dir, load.input);
  if (!p) return p.error();
  load.text << "PRM: " << p->cluster_count << " clusters, K = " << load.settings.prm_active_clusters
            << ", relit when a moving light changes\n";
  auto caster = load.static_world();
  if (!caster) return caster.error();
  auto lighting =
      PrmLighting::from_bake(std::move(p).value(), load.atlas_bake ? &*load.atlas_bake : nullptr, load.scene,
                             {.active_clusters = load.settings.prm_active_clusters,
                              .log = load.settings.log,
                              .shared_exponent_panes = load.settings.prm_shared_exponent_panes},
                             std::move(caster).value());
  if (!lighting) return lighting.error();
  if (load.layout == nullptr) {
    load.layout = &lighting.value()->layout();
    load.atlas_width = load.layout->width;
    load.atlas_height = load.layout->height;
  }
  load.moving_lights = lighting.value().get();
  return std::unique_ptr<MethodRuntime>(new PrmMethod(std::move(lighting).value()));
}

}  // namespace gi
