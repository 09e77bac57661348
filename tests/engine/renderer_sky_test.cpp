// The renderer's sky term (RenderSettings::sky_radiance / sky_gradient, docs/scene-format.md):
// a gradient sky lights an upward plane with its analytic irradiance.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <engine/gltf_brdf.h>
#include <engine/sky.h>

#include <cmath>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr float kAlbedo = 0.6f;

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
  s.assets.environment.sky_gradient = {.zenith = {2.0f, 1.0f, 1.0f}, .horizon = {0.5f, 1.0f, 1.0f}, .ground = {9.0f, 9.0f, 9.0f}};
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

}  // namespace
