#pragma once
// The runtime side of a baked light atlas: an engine::IndirectLightProvider that hands the
// renderer the atlas as a texture, which it samples at TEXCOORD_1 of static meshes.
//   auto gi = gi::LightAtlasLighting::load("level.gibake", scene);  // before Renderer::create
//   if (!gi) { std::cerr << gi.error().to_string() << '\n'; return 1; }
//   auto renderer = engine::Renderer::create(scene.assets, settings).value();
//   renderer->set_indirect_light(gi.value().get());
//
// Loading replaces the scene's assets by a copy carrying the atlas parameterization as
// TEXCOORD_1 (gi::with_atlas_uv1: static meshes get uv1, vertices on chart borders are
// split, a mesh shared by several static nodes is duplicated), so create the renderer from
// the scene after loading. Dynamic meshes get no indirect light from this provider.
// The GL texture is created on the first frame() (the GL context must be current then) and
// deleted with the provider: destroy it before the GL context.

#include <engine/gpu/gl_objects.h>
#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <engine/scene_asset.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

namespace gi {

struct LightAtlasBake;

class LightAtlasLighting final : public engine::IndirectLightProvider {
 public:
  /// Loads the light atlas of `bundle_dir` baked for `asset` (a bundle baked from other
  /// geometry is an error) and replaces `asset` with its uv1 copy. On error `asset` is
  /// unchanged. Use before engine::instantiate().
  static engine::Result<std::unique_ptr<LightAtlasLighting>> load(const std::filesystem::path& bundle_dir,
                                                                  engine::SceneAsset& asset);
  /// The same for a scene already instantiated: replaces `scene.assets` and points the
  /// MeshRenderer of every node whose mesh was duplicated at its copy.
  static engine::Result<std::unique_ptr<LightAtlasLighting>> load(const std::filesystem::path& bundle_dir,
                                                                  engine::Scene& scene);
  /// From a bake in memory (its layout must come from atlas_inputs_from(asset)); replaces
  /// `asset` with its uv1 copy. Error when the layout does not match the asset.
  static engine::Result<std::unique_ptr<LightAtlasLighting>> from_bake(LightAtlasBake bake, engine::SceneAsset& asset);
  /// The same for a scene already instantiated (see load(bundle_dir, scene)).
  static engine::Result<std::unique_ptr<LightAtlasLighting>> from_bake(const LightAtlasBake& bake, engine::Scene& scene);

  LightAtlasLighting(const LightAtlasLighting&) = delete;
  LightAtlasLighting& operator=(const LightAtlasLighting&) = delete;
  ~LightAtlasLighting() override;

  /// The atlas texture (RGBA32F: RGB irradiance in W/m^2, A = 1 on texels a triangle
  /// covers; linear filtering, clamped to the edge), uploaded on the first call.
  const engine::IndirectLightFrame& frame() override;
  /// "light atlas".
  const char* label() const override { return "light atlas"; }

  int atlas_width() const { return width_; }
  int atlas_height() const { return height_; }

 private:
  LightAtlasLighting(int width, int height, std::vector<float> rgba);

  int width_ = 0;
  int height_ = 0;
  std::vector<float> rgba_;  ///< Texels to upload; released after the upload.
  engine::GlTexture texture_;
  engine::IndirectLightFrame frame_;
};

}  // namespace gi
