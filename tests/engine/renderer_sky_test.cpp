// The renderer's sky term (RenderSettings::sky_radiance / sky_gradient, docs/scene-format.md):
// a gradient sky lights an upward plane with its analytic irradiance, and a provider's sky visibility
// (IndirectLightFrame::sky_visibility) darkens the sky term of a dynamic entity and of nothing else. A provider whose
// atlas holds the sky, or the static lights' direct light (IndirectLightFrame::atlas_holds_*), replaces those terms on
// the static surfaces that read it, and on nothing else: nothing is drawn twice.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <engine/gltf_brdf.h>
#include <engine/sky.h>

#include <cmath>
#include <cstdio>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr float kAlbedo = 0.6f;

// No atlas, no vertex buffer; the dynamic entity's +Y face sees a quarter of the sky.
class SkyOcclusion : public engine::IndirectLightProvider {
 public:
  struct Frame : engine::IndirectLightFrame {
    engine::Entity dynamic;
    bool sky_visibility(engine::Entity e, float (&axes)[6]) const override {
      if (e != dynamic) return false;
      for (float& a : axes) a = 1.0f;
      axes[2] = 0.25f;  // +Y
      return true;
    }
  };
  const engine::IndirectLightFrame& frame() override { return frame_; }
  const char* label() const override { return "test sky occlusion"; }
  Frame frame_;
};

struct TwoPlanes {
  engine::SceneAsset assets;
  engine::Registry reg;
  engine::Entity dynamic;
  TestCamera cam{{0.0f, 4.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  engine::Entity camera;

  TwoPlanes() {
    assets.materials.push_back(diffuse_material(kAlbedo));
    assets.meshes.push_back(plane_mesh(1.0f, 0));
    add_mesh(reg, 0, glm::translate(glm::mat4(1.0f), glm::vec3(-1.2f, 0, 0)), /*is_static=*/true);
    dynamic = add_mesh(reg, 0, glm::translate(glm::mat4(1.0f), glm::vec3(1.2f, 0, 0)), /*is_static=*/false);
    camera = cam.add_to(reg);
  }
  // The directional albedo (both lobes) of the planes seen from the camera at x.
  float albedo_at(float x) const {
    const float cos_v = 4.0f / std::sqrt(16.0f + x * x);
    return engine::gltf_directional_albedo(engine::gltf_brdf(glm::vec3(kAlbedo), 0.0f, 1.0f), cos_v).sum().x;
  }
};

TEST(RendererSky, GradientSkyLightsAnUpwardPlaneWithItsIrradiance) {
  engine::GpuContext ctx = headless_context();
  TwoPlanes s;
  s.assets.environment.sky_gradient = {
      .zenith = {2.0f, 1.0f, 1.0f}, .horizon = {0.5f, 1.0f, 1.0f}, .ground = {9.0f, 9.0f, 9.0f}};
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->settings().sky_gradient, s.assets.environment.sky_gradient);
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF img = r->read_hdr();
  // Exact: E_up = pi/3 horizon + 2 pi/3 zenith (the ground, bright here, is below the plane).
  const float e_up = engine::sky_irradiance_up(glm::vec3(0.0f), s.assets.environment.sky_gradient).x;
  const float expected = e_up / kPi * s.albedo_at(1.2f);
  EXPECT_NEAR(red(img, s.cam.pixel_of({-1.2f, 0, 0})), expected, 0.01f * expected);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(RendererSky, ProviderSkyVisibilityDarkensOnlyTheDynamicEntity) {
  engine::GpuContext ctx = headless_context();
  TwoPlanes s;
  s.assets.environment.sky_radiance = glm::vec3(1.0f);
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  SkyOcclusion provider;
  provider.frame_.dynamic = s.dynamic;
  r->set_indirect_light(&provider);
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF img = r->read_hdr();
  const float open = 1.0f * s.albedo_at(1.2f);  // L x directional albedo
  EXPECT_NEAR(red(img, s.cam.pixel_of({-1.2f, 0, 0})), open, 0.01f * open) << "static: unoccluded";
  EXPECT_NEAR(red(img, s.cam.pixel_of({1.2f, 0, 0})), 0.25f * open, 0.01f * open) << "dynamic: its +Y visibility";
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// A provider whose irradiance atlas is one texel of irradiance `e` (W/m^2) read by every
// static mesh (the planes have no TEXCOORD_1: all read texel 0).
class UniformAtlas : public engine::IndirectLightProvider {
 public:
  explicit UniformAtlas(glm::vec3 e) {
    glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
    glTextureStorage2D(texture_, 1, GL_RGBA32F, 1, 1);
    const float texel[4] = {e.x, e.y, e.z, 1.0f};
    glTextureSubImage2D(texture_, 0, 0, 0, 1, 1, GL_RGBA, GL_FLOAT, texel);
    frame_.irradiance_atlas_texture = {texture_};
  }
  ~UniformAtlas() override { glDeleteTextures(1, &texture_); }
  UniformAtlas(const UniformAtlas&) = delete;
  UniformAtlas& operator=(const UniformAtlas&) = delete;
  const engine::IndirectLightFrame& frame() override { return frame_; }
  const char* label() const override { return "test uniform atlas"; }
  engine::IndirectLightFrame frame_;

 private:
  GLuint texture_ = 0;
};

TEST(RendererSky, AnAtlasThatHoldsTheSkyReplacesTheSkyTermOnStaticSurfacesOnly) {
  engine::GpuContext ctx = headless_context();
  TwoPlanes s;
  s.assets.environment.sky_radiance = glm::vec3(1.0f);
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const float baked = 0.8f;  // W/m^2: the sky's shadowed irradiance, as a bake would hold it
  UniformAtlas atlas{glm::vec3(baked)};
  r->set_indirect_light(&atlas);
  const float open = 1.0f * s.albedo_at(1.2f);  // the sky term: L x directional albedo
  const float from_atlas = baked / kPi * s.albedo_at(1.2f);
  r->render(s.reg, s.camera);
  engine::ImageRgbaF img = r->read_hdr();
  EXPECT_NEAR(red(img, s.cam.pixel_of({-1.2f, 0, 0})), open + from_atlas, 0.01f * open)
      << "static, atlas of indirect light only";
  atlas.frame_.atlas_holds_sky = true;
  r->render(s.reg, s.camera);
  img = r->read_hdr();
  EXPECT_NEAR(red(img, s.cam.pixel_of({-1.2f, 0, 0})), from_atlas, 0.01f * from_atlas)
      << "static: the atlas's sky alone";
  EXPECT_NEAR(red(img, s.cam.pixel_of({1.2f, 0, 0})), open, 0.01f * open)
      << "dynamic: reads no atlas, keeps the sky term";
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// A static light (moves false) and a moving one, 1 m above the two planes. With an atlas that
// holds the static lights' direct light, a static plane is lit by the moving light alone (the
// atlas, 0 here, stands for the rest); the dynamic plane by both, as without the flag.
TEST(RendererSky, AnAtlasThatHoldsTheStaticLightsLeavesOnlyMovingLightsLiveOnStaticSurfaces) {
  engine::GpuContext ctx = headless_context();
  TwoPlanes s;
  engine::Light fixed{.type = engine::LightType::Point, .intensity = 2.0f, .cast_shadows = false};
  engine::Light moving{.type = engine::LightType::Point, .intensity = 1.0f, .moves = true, .cast_shadows = false};
  const engine::Entity fixed_light = add_light(s.reg, fixed, {0.0f, 1.0f, 0.3f}, {0.0f, 0.0f, 0.3f});
  add_light(s.reg, moving, {0.0f, 1.0f, -0.3f}, {0.0f, 0.0f, -0.3f});
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  UniformAtlas atlas{glm::vec3(0.0f)};
  r->set_indirect_light(&atlas);
  const glm::ivec2 on_static = s.cam.pixel_of({-1.2f, 0, 0}), on_dynamic = s.cam.pixel_of({1.2f, 0, 0});
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF both = r->read_hdr();
  s.reg.write<engine::Light>(fixed_light).enabled = false;
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF moving_only = r->read_hdr();
  s.reg.write<engine::Light>(fixed_light).enabled = true;
  atlas.frame_.atlas_holds_static_lights = true;
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF held = r->read_hdr();
  ASSERT_GT(red(both, on_static), 1.5f * red(moving_only, on_static)) << "the static light must matter";
  EXPECT_NEAR(red(held, on_static), red(moving_only, on_static), 1e-5f) << "static: the moving light alone";
  EXPECT_NEAR(red(held, on_dynamic), red(both, on_dynamic), 1e-5f) << "dynamic: both lights live";
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// The sun's disc in the renderer (shadow_common.glsl's shadow_2d_disc): a plate 1 m above a
// floor, covering x < 0, the sun straight overhead. The 10-90% width of the shadow edge on
// the floor follows the disc: the geometry's is 1.37 R for a disc (R = h tan r; 2 R the whole
// penumbra). The renderer's taps spread uniformly over a disc of radius b tan r must give it
// within 15% (a 5x5 square grid of taps over +-b tan r gave 0.173 m, 1.98 R, before; 0.0806 m
// while the taps' radius was capped at 48 texels of the 4096 sun map), and
// the point sun's edge stays a few texels.
double edge_width(float angular_radius_rad) {
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(kAlbedo));
  assets.meshes.push_back(plane_mesh(2.0f, 0));
  engine::Mesh plate;
  plate.name = "plate";
  plate.primitives.emplace_back();
  plate.primitives[0].material = 0;
  add_quad(plate.primitives[0], glm::vec3(-1.5f, 1.0f, 0.0f), glm::vec3(0, 0, 1.5f),
           glm::vec3(1.5f, 0, 0));  // faces up
  assets.meshes.push_back(plate);
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  add_mesh(reg, 1, glm::mat4(1.0f));
  engine::Light sun{.type = engine::LightType::Directional, .intensity = 10.0f};
  sun.angular_radius_rad = angular_radius_rad;
  add_light(reg, sun, {0.0f, 5.0f, 0.0f}, {0.0f, 0.0f, 0.0f});
  TestCamera cam{{0.0f, 0.6f, 1.2f}, {0.0f, 0.0f, 0.0f}, 0.8f, 129};
  const engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, cam.size, 0.0f);
  if (!r) return 0.0;
  r->settings().shadow_map_size = 1024;
  r->render(reg, camera);
  const engine::ImageRgbaF img = r->read_hdr();
  const float lit = red(img, cam.pixel_of({0.4f, 0, 0})), dark = red(img, cam.pixel_of({-0.4f, 0, 0}));
  EXPECT_GT(lit, 10.0f * dark + 1e-3f);
  // Along the image row through (0, 0, 0): x of each pixel on the floor and its lit fraction.
  const glm::ivec2 centre = cam.pixel_of({0, 0, 0});
  double x10 = 0.0, x90 = 0.0, prev_x = -1.0, prev_f = 0.0;
  for (int px = 0; px < cam.size; ++px) {
    const double x = static_cast<double>(cam.plane_point(px, centre.y).x);
    const double f = static_cast<double>((red(img, px, centre.y) - dark) / (lit - dark));
    if (px > 0 && prev_f < 0.1 && f >= 0.1) x10 = prev_x + (0.1 - prev_f) / (f - prev_f) * (x - prev_x);
    if (px > 0 && prev_f < 0.9 && f >= 0.9) x90 = prev_x + (0.9 - prev_f) / (f - prev_f) * (x - prev_x);
    prev_x = x;
    prev_f = f;
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  return x90 - x10;
}

TEST(RendererSky, SunDiscWidensTheShadowEdge) {
  engine::GpuContext ctx = headless_context();
  const float r = 5.0f * kPi / 180.0f;
  const double big_r = std::tan(static_cast<double>(r));  // h = 1 m
  const double soft = edge_width(r), hard = edge_width(0.0f);
  std::printf(
      "renderer shadow edge 10-90%%: sun radius 5 deg %.4f m (disc geometry 1.37 R = %.4f, a square box 1.6 R = %.4f); "
      "point sun %.4f m\n",
      soft, 1.374 * big_r, 1.6 * big_r, hard);
  EXPECT_NEAR(soft, 1.374 * big_r, 0.15 * 1.374 * big_r);
  EXPECT_LT(hard, 0.5 * soft);
}

}  // namespace
