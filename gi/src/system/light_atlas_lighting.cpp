#include "system/light_atlas_lighting.h"

#include <GL/glcorearb.h>

#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "uv/atlas_scene_writer.h"

namespace gi {

namespace {

// RGB irradiance and the validity mask as RGBA texels, the upload format.
std::vector<float> rgba_of(const LightAtlasBake& bake) {
  std::vector<float> rgba(bake.irradiance.size() * 4);
  for (std::size_t i = 0; i < bake.irradiance.size(); ++i) {
    rgba[4 * i + 0] = bake.irradiance[i].x;
    rgba[4 * i + 1] = bake.irradiance[i].y;
    rgba[4 * i + 2] = bake.irradiance[i].z;
    rgba[4 * i + 3] = bake.valid[i] != 0 ? 1.0f : 0.0f;
  }
  return rgba;
}

}  // namespace

LightAtlasLighting::LightAtlasLighting(int width, int height, std::vector<float> rgba, bool holds_static_lights)
    : width_(width), height_(height), rgba_(std::move(rgba)) {
  frame_.atlas_holds_sky = true;  // light_atlas.h: LightAtlasBake::irradiance
  frame_.atlas_holds_static_lights = holds_static_lights;
}

LightAtlasLighting::~LightAtlasLighting() = default;

engine::Result<std::unique_ptr<LightAtlasLighting>> LightAtlasLighting::from_bake(LightAtlasBake bake,
                                                                                  engine::SceneAsset& asset) {
  const std::size_t texels =
      static_cast<std::size_t>(std::max(bake.width, 0)) * static_cast<std::size_t>(std::max(bake.height, 0));
  if (bake.width <= 0 || bake.height <= 0 || bake.irradiance.size() != texels || bake.valid.size() != texels)
    return engine::Error{
        asset.source, "light atlas",
        "the bake's arrays do not hold " + std::to_string(bake.width) + "x" + std::to_string(bake.height) + " texels"};
  if (bake.width != bake.layout.width || bake.height != bake.layout.height)
    return engine::Error{asset.source, "light atlas", "the bake's size differs from its layout's"};
  auto with_uv1 = with_atlas_uv1(asset, bake.layout);
  if (!with_uv1) return with_uv1.error();
  asset = std::move(with_uv1).value();
  return std::unique_ptr<LightAtlasLighting>(
      new LightAtlasLighting(bake.width, bake.height, rgba_of(bake), bake.settings.include_direct));
}

engine::Result<std::unique_ptr<LightAtlasLighting>> LightAtlasLighting::from_bake(const LightAtlasBake& bake,
                                                                                  const engine::Scene& scene) {
  auto meshes = atlas_meshes_of(scene, bake.layout);
  if (!meshes) return meshes.error();
  auto out = std::unique_ptr<LightAtlasLighting>(
      new LightAtlasLighting(bake.width, bake.height, rgba_of(bake), bake.settings.include_direct));
  out->atlas_meshes_ = std::move(meshes).value();
  return out;
}

const engine::IndirectLightFrame& LightAtlasLighting::frame() {
  if (texture_.empty()) {
    engine::GlTexture texture = engine::GlTexture::create_2d(GL_RGBA32F, width_, height_);
    glTextureSubImage2D(texture.id(), 0, 0, 0, width_, height_, GL_RGBA, GL_FLOAT, rgba_.data());
    glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    frame_.irradiance_atlas_texture = {texture.id()};
    texture_ = std::move(texture);
    rgba_ = {};
  }
  return frame_;
}

}  // namespace gi
