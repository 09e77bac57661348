// The light atlas at run time: the static lights' (and the sky's) baked irradiance, uploaded
// once. Publishes its bake for the methods after it (the layout; the VPLs the BRF's world
// probes are lit by).

#include "light_atlas/light_atlas_io.h"
#include "system/light_atlas_lighting.h"
#include "system/method_table.h"

namespace gi {

namespace {

class LightAtlasMethod final : public MethodRuntime {
 public:
  explicit LightAtlasMethod(std::unique_ptr<LightAtlasLighting> lighting) : lighting_(std::move(lighting)) {}
  void frame(FrameState& state) override {
    state.atlas_texture = lighting_->frame().irradiance_atlas_texture.gl_name;
    state.atlas_changed = !shown_;
    shown_ = true;
  }
  std::string label() const override { return lighting_->label(); }
  std::span<const engine::AtlasMesh> atlas_meshes() const override { return lighting_->atlas_meshes(); }

 private:
  std::unique_ptr<LightAtlasLighting> lighting_;
  bool shown_ = false;
};

}  // namespace

engine::Result<std::unique_ptr<MethodRuntime>> load_light_atlas_method(MethodLoad& load) {
  auto a = load_light_atlas(load.bundle_dir, load.input);
  if (!a) return a.error();
  const LightAtlasBake& atlas = load.atlas_bake.emplace(std::move(a).value());
  load.layout = &atlas.layout;
  load.atlas_width = atlas.width;
  load.atlas_height = atlas.height;
  load.text << "light atlas: " << atlas.width << "x" << atlas.height << ", static lights, " << atlas.settings.bounces
            << " bounces\n";
  // The atlas (alone or under the PRM's panes) holds the sky's direct light, and every static
  // light's with include_direct: the renderer draws neither again on the static world.
  load.frame.atlas_holds_sky = true;
  load.frame.atlas_holds_static_lights = atlas.settings.include_direct;
  if (load.is_superseded(EffectMethod::LightAtlas)) return std::unique_ptr<MethodRuntime>();
  auto lighting = LightAtlasLighting::from_bake(atlas, load.scene);
  if (!lighting) return lighting.error();
  return std::unique_ptr<MethodRuntime>(new LightAtlasMethod(std::move(lighting).value()));
}

}  // namespace gi
