#pragma once
// The runtime side of a baked light atlas (internal to GISystem, which loads bundles): an
// engine::IndirectLightProvider that hands the renderer the atlas as a texture, which it
// samples at TEXCOORD_1 of static meshes.
//   auto gi = gi::LightAtlasLighting::from_bake(bake, scene).value();
//   renderer->set_indirect_light(gi.get());
//
// The scene is left as it is: the static meshes with the atlas parameterization as
// TEXCOORD_1 (gi::atlas_meshes_of: vertices on chart borders split, one mesh per static
// instance) go to the renderer through atlas_meshes(). Dynamic meshes get no indirect light from this provider. The GL
// texture is created on the first frame() (the GL context must be current then) and deleted with the provider: destroy
// it before the GL context.

#include <engine/gpu/gl_objects.h>
#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <engine/scene_asset.h>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace gi {

struct LightAtlasBake;

class LightAtlasLighting final : public engine::IndirectLightProvider {
 public:
  /// From a bake (its layout must come from atlas_inputs_from(bake_input_from(asset)));
  /// replaces `asset` with its uv1 copy. Error when the layout does not match the asset.
  static engine::Result<std::unique_ptr<LightAtlasLighting>> from_bake(LightAtlasBake bake, engine::SceneAsset& asset);
  /// For a scene already instantiated, which stays unchanged: the static meshes with the
  /// atlas's TEXCOORD_1 are handed to the renderer by atlas_meshes().
  static engine::Result<std::unique_ptr<LightAtlasLighting>> from_bake(const LightAtlasBake& bake,
                                                                       const engine::Scene& scene);

  LightAtlasLighting(const LightAtlasLighting&) = delete;
  LightAtlasLighting& operator=(const LightAtlasLighting&) = delete;
  ~LightAtlasLighting() override;

  /// The atlas texture (RGBA32F: RGB irradiance in W/m^2, A = 1 on texels a triangle
  /// covers; linear filtering, clamped to the edge), uploaded on the first call; it holds the
  /// sky's direct light, and the static lights' with include_direct (atlas_holds_*).
  const engine::IndirectLightFrame& frame() override;
  /// "light atlas".
  const char* label() const override { return "light atlas"; }
  /// The static meshes with the atlas's TEXCOORD_1 (empty from the SceneAsset overload,
  /// whose asset holds them).
  std::span<const engine::AtlasMesh> atlas_meshes() const override { return atlas_meshes_; }

  int atlas_width() const { return width_; }
  int atlas_height() const { return height_; }

 private:
  LightAtlasLighting(int width, int height, std::vector<float> rgba, bool holds_static_lights);

  int width_ = 0;
  int height_ = 0;
  std::vector<float> rgba_;  ///< Texels to upload; released after the upload.
  engine::GlTexture texture_;
  engine::IndirectLightFrame frame_;
  std::vector<engine::AtlasMesh> atlas_meshes_;
};

}  // namespace gi
