// Antiradiance at run time: on frames where a deforming node moved, its elements relinked and
// the iteration run on the GPU; the change against the baked pose is added into the static
// world's atlas (docs/antiradiance.md).

#include "antiradiance/antiradiance_io.h"
#include "system/antiradiance_lighting.h"
#include "system/method_table.h"

namespace gi {

namespace {

class AntiradianceMethod final : public MethodRuntime {
 public:
  explicit AntiradianceMethod(std::unique_ptr<AntiradianceLighting> lighting) : lighting_(std::move(lighting)) {}
  void frame(FrameState& state) override {
    if (!lighting_->disabled().empty() || state.atlas_texture == 0) return;
    const bool moved = lighting_->update();
    if (!lighting_->disabled().empty()) return;  // turned off now: GISystem tells the stats
    const std::uint32_t out = atlas_target_like(state.atlas_texture, out_);
    if (moved || state.atlas_changed || state.objects_changed || !composed_) {
      lighting_->composite(state.atlas_texture, out);
      composed_ = true;
    }
    state.atlas_texture = out;
    if (moved) {
      state.work = true;
      ++state.stats.antiradiance_updates;
      state.stats.antiradiance_relinked_elements = lighting_->stats().relinked_elements;
      state.stats.last_antiradiance_ms = lighting_->stats().last_ms;
      state.stats.antiradiance_iterations = lighting_->stats().iterations;
      state.stats.antiradiance_residual = lighting_->stats().residual;
      state.stats.antiradiance_unconverged = lighting_->stats().unconverged;
      state.stats.antiradiance_warm = lighting_->stats().warm;
      state.stats.antiradiance_near_ms = lighting_->stats().near_ms;
    }
  }
  std::string label() const override { return "antiradiance"; }
  std::string disabled() const override { return lighting_->disabled(); }

 private:
  std::unique_ptr<AntiradianceLighting> lighting_;
  engine::GlTexture out_;
  bool composed_ = false;
};

}  // namespace

engine::Result<std::unique_ptr<MethodRuntime>> load_antiradiance_method(MethodLoad& load) {
  if (load.layout == nullptr)
    return engine::Error{(load.bundle_dir / "manifest.json").string(), "methods.antiradiance",
                         "antiradiance adds into the light atlas: the bundle needs a light atlas or a PRM too"};
  auto bake = load_antiradiance(load.bundle_dir, load.input);
  if (!bake) return bake.error();
  auto anti = AntiradianceLighting::create(std::move(bake).value(), load.input, *load.layout, load.scene.registry,
                                           load.settings.log);
  if (!anti) return anti.error();
  const auto& st = anti.value()->stats();
  load.text << "antiradiance: " << st.elements << " elements, " << st.links << " links, " << st.covered_texels
            << " atlas texels; solved on frames where a deforming node moves\n";
  if (st.near_visibility)
    load.text << "antiradiance: near-door visibility for " << st.near_receivers << " leaves (their couplings "
              << static_cast<long long>(st.near_load_ms) << " ms at load, "
              << static_cast<double>(st.near_table_bytes) / 1e6 << " MB)\n";
  else if (st.near_fell_back)
    load.text << "antiradiance: near-door visibility OFF, antiradiance alone: " << anti.value()->near_fell_back_reason()
              << "\n";
  return std::unique_ptr<MethodRuntime>(new AntiradianceMethod(std::move(anti).value()));
}

}  // namespace gi
