// An area light's shadow beyond its 2-D map: the map covers 150 degrees around the light's
// normal, the rectangle lights its whole front half-space. A receiver in the grazing band
// (75-90 degrees off the normal) behind a wall must be dark (the hub panel's light leaked
// through the hub's wall onto the crate room's upper walls, docs/performance-frame.md).
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <cstdio>
#include <tuple>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr int kSize = 64;

// A 0.5 m area light 2 m up facing down; a receiver wall at x = 3 facing the light (y 1.4 to
// 1.9: 82-85 degrees off the light's normal, seen from its centre); optionally a blocking wall
// at x = 1.5 (y 0 to 2.5) between them. The camera stands between the walls, looking at the
// receiver. Light reach is off: the shadow maps alone decide.
float receiver_radiance(bool blocker, engine::AreaShadowRes res, bool soft) {
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(0.5f));
  engine::Mesh walls;
  walls.name = "walls";
  walls.primitives.emplace_back();
  walls.primitives[0].material = 0;
  // Receiver: normal -X (towards the light); add_quad's normal is u x v.
  add_quad(walls.primitives[0], glm::vec3(3.0f, 1.65f, 0.0f), glm::vec3(0, 0, 1.0f), glm::vec3(0, 0.25f, 0));
  assets.meshes.push_back(walls);
  engine::Mesh wall;
  wall.name = "blocker";
  wall.primitives.emplace_back();
  wall.primitives[0].material = 0;
  add_quad(wall.primitives[0], glm::vec3(1.5f, 1.25f, 0.0f), glm::vec3(0, 1.25f, 0), glm::vec3(0, 0, 2.0f));
  assets.meshes.push_back(wall);
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  if (blocker) add_mesh(reg, 1, glm::mat4(1.0f));
  add_light(reg, engine::Light{.type = engine::LightType::Area, .intensity = 200.0f, .area_size_m = {0.5f, 0.5f}},
            {0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f});
  const TestCamera cam{{2.2f, 1.65f, 0.0f}, {3.0f, 1.65f, 0.0f}, 0.5f, kSize};
  const engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, kSize, 0.0f);
  if (!r) return -1.0f;
  r->settings().light_reach_culling = false;
  r->settings().area_shadow_res = res;
  r->settings().area_soft_shadows = soft;
  r->render(reg, camera);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  const engine::ImageRgbaF img = r->read_hdr();
  return red(img, kSize / 2, kSize / 2);
}

}  // namespace

TEST(RendererAreaGrazing, WallBlocksTheAreaLightBeyondItsShadowMap) {
  engine::GpuContext ctx = headless_context();
  const float open = receiver_radiance(false, engine::AreaShadowRes::Full, true);
  std::printf("receiver in the grazing band, no wall: %.5f\n", static_cast<double>(open));
  ASSERT_GT(open, 1e-3f) << "the receiver must be lit by the area light without the wall";
  for (const auto& [res, soft, name] : {std::tuple{engine::AreaShadowRes::Full, true, "soft, full res"},
                                        std::tuple{engine::AreaShadowRes::Half, true, "soft, half res"},
                                        std::tuple{engine::AreaShadowRes::Full, false, "centre"}}) {
    const float walled = receiver_radiance(true, res, soft);
    std::printf("behind the wall (%s): %.5f\n", name, static_cast<double>(walled));
    EXPECT_LT(walled, 0.01f * open) << name << ": the wall must block the light beyond the 150 degree map";
  }
}
