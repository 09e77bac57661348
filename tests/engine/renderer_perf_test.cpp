// Frame cost of the renderer at 960x540 on a ~10k-triangle scene with 4 shadowed lights
// (point, spot, directional, area). Prints per-pass milliseconds (CPU wall time on
// llvmpipe: glFinish + steady clock) and checks the timings are reported.
//   ctest --test-dir build -R RendererPerf --output-on-failure -V
#include <algorithm>
#include <cstdio>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

TEST(RendererPerf, ForwardPassAt960x540With4ShadowedLights) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(0.6f));
  assets.materials.push_back(diffuse_material(0.8f, 0.3f));
  assets.meshes.push_back(plane_mesh(12.0f, 0));
  assets.meshes.push_back(box_mesh(glm::vec3(0.2f), 1));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  int triangles = 2;
  for (int z = 0; z < 29; ++z)
    for (int x = 0; x < 29; ++x) {  // 841 boxes x 12 triangles
      const glm::vec3 p(-7.0f + 0.5f * static_cast<float>(x), 0.2f + 0.1f * static_cast<float>((x * 7 + z * 3) % 5),
                        -7.0f + 0.5f * static_cast<float>(z));
      add_mesh(reg, 1, glm::translate(glm::mat4(1.0f), p));
      triangles += 12;
    }
  add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 20.0f}, {-2, 3, 1}, {0, 0, 0});
  add_light(reg, engine::Light{.type = engine::LightType::Spot, .intensity = 40.0f, .outer_cone_rad = 0.6f}, {3, 4, -2},
            {0, 0, 0});
  add_light(reg, engine::Light{.type = engine::LightType::Directional, .intensity = 2.0f}, {1, 5, 2}, {0, 0, 0});
  add_light(reg, engine::Light{.type = engine::LightType::Area, .intensity = 30.0f, .area_size_m = {1.0f, 0.5f}},
            {0, 3, -4}, {0, 0, -3});
  engine::Entity camera = add_entity(reg, looking_at({0, 6, 9}, {0, 0, 0}));
  reg.emplace<engine::Camera>(camera, engine::Camera{});

  engine::RenderSettings settings;  // 960x540, 1024^2 shadow maps (cube faces 512^2)
  auto r = engine::Renderer::create(assets, settings);
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  constexpr int kFrames = 2;
  std::vector<double> ms[3];
  for (int f = 0; f < kFrames + 1; ++f) {
    r.value()->render(reg, camera);
    const auto& t = r.value()->last_timings();
    ASSERT_EQ(t.size(), 3u);
    if (f == 0) continue;  // warm-up (shader variants, first-touch allocations)
    for (int i = 0; i < 3; ++i) {
      EXPECT_GT(t[static_cast<std::size_t>(i)].ms, 0.0);
      ms[i].push_back(t[static_cast<std::size_t>(i)].ms);
    }
  }
  const auto& names = r.value()->last_timings();
  std::printf("renderer: %d triangles, 4 shadowed lights, %dx%d, median of %d frames (llvmpipe, wall time):\n",
              triangles, settings.width, settings.height, kFrames);
  for (int i = 0; i < 3; ++i) {
    std::sort(ms[i].begin(), ms[i].end());
    const double median = 0.5 * (ms[i][kFrames / 2 - 1] + ms[i][kFrames / 2]);
    std::printf("  %-45s %8.1f ms\n", names[static_cast<std::size_t>(i)].name.c_str(), median);
    RecordProperty("pass_" + std::to_string(i) + "_ms", std::to_string(median));
  }
  // The area-light specular's other settings in the same run (the default, 0, is the fitted
  // transforms of sharp lobes and 3 x 3 points for wide ones): 3 x 3 points everywhere, and the
  // cheapest (one point per rectangle). Warm-up frame + one frame each.
  for (int side : {3, 1}) {
    r.value()->settings().area_specular_samples_per_side = side;
    r.value()->render(reg, camera);
    r.value()->render(reg, camera);
    std::printf("  %-45s %8.1f ms (area_specular_samples_per_side = %d)\n", r.value()->last_timings()[1].name.c_str(),
                r.value()->last_timings()[1].ms, side);
  }
  const engine::ImageRgba8 ldr = r.value()->read_ldr();
  EXPECT_EQ(ldr.width, 960);
  EXPECT_EQ(ldr.height, 540);
}

}  // namespace
