// Run-time inputs gone bad (issue 20, docs/reliability.md): a moving light or a dynamic
// object whose transform, intensity or colour becomes NaN, infinite or absurd mid-game is
// skipped with one warning from the GI system and one from the renderer, and everything
// stays finite — the PRM's atlas, the BRF's per-vertex light, the rendered HDR frame. When
// the values are good again the frame is what it was. Real GL on llvmpipe (never skipped).
#define GL_GLEXT_PROTOTYPES 1
#include <unistd.h>
#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/renderer.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "gl_readback.h"

namespace {

namespace fs = std::filesystem;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

engine::Scene crates_room_with_a_moving_light() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf");
  EXPECT_TRUE(asset) << asset.error().to_string();
  engine::Scene scene = engine::instantiate(std::move(asset.value()));
  const engine::Entity light = engine::find_by_name(scene.registry, "ceiling_light");
  EXPECT_FALSE(light.is_null());
  scene.registry.write<engine::Light>(light).moves = true;  // the PRM lights it
  return scene;
}

std::size_t non_finite(const std::vector<glm::vec3>& v) {
  std::size_t n = 0;
  for (const glm::vec3& x : v) n += !(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
  return n;
}

std::size_t non_finite(const engine::ImageRgbaF& img) {
  std::size_t n = 0;
  for (float x : img.pixels) n += !std::isfinite(x);
  return n;
}

TEST(RuntimeInputs, NanOrAbsurdLightsAndObjectsAreSkippedOnceAndEverythingStaysFinite) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  const fs::path dir = fs::temp_directory_path() / ("runtime_inputs_" + std::to_string(::getpid()) + ".gibake");
  fs::remove_all(dir);
  {
    engine::Scene scene = crates_room_with_a_moving_light();
    auto baked =
        gi::bake_bundle(gi::bake_input_from(scene), dir,
                        {.preset = "preview", .methods = {"light_atlas", "prm", "brf"}, .texels_per_metre = 4.0f});
    ASSERT_TRUE(baked) << baked.error().to_string();
  }
  engine::Scene scene = crates_room_with_a_moving_light();
  std::vector<std::string> gi_warnings, render_warnings;
  gi::GISystemSettings settings;
  settings.log = [&](gi::LogLevel level, std::string_view line) {
    if (level == gi::LogLevel::Warning) gi_warnings.emplace_back(line);
  };
  auto loaded = gi::GISystem::load(dir, scene, settings);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  EXPECT_STREQ(gi.label(), "light atlas + PRM + BRF");
  engine::RenderSettings rs;
  rs.width = 160;
  rs.height = 90;
  rs.warn = [&](const std::string& line) { render_warnings.push_back(line); };
  auto renderer = engine::Renderer::create(scene.assets, rs);
  ASSERT_TRUE(renderer) << renderer.error().to_string();
  (*renderer)->set_indirect_light(&gi);
  const engine::Entity camera = engine::find_camera(scene.registry);
  const engine::Entity light = engine::find_by_name(scene.registry, "ceiling_light");
  const engine::Entity crate = engine::find_by_name(scene.registry, "crate_1");
  ASSERT_FALSE(camera.is_null() || light.is_null() || crate.is_null());

  int atlas_w = 0, atlas_h = 0;
  const auto frame = [&] {
    gi.frame();
    (*renderer)->render(scene.registry, camera);
    const std::uint32_t atlas = gi.frame().irradiance_atlas_texture.gl_name;
    glGetTextureLevelParameteriv(atlas, 0, GL_TEXTURE_WIDTH, &atlas_w);
    glGetTextureLevelParameteriv(atlas, 0, GL_TEXTURE_HEIGHT, &atlas_h);
    return (*renderer)->read_hdr();
  };
  const auto crate_light = [&] {
    const std::uint32_t buffer = gi.frame().vertex_irradiance_buffer(crate).gl_name;
    GLint64 bytes = 0;
    glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &bytes);
    std::vector<glm::vec4> v(static_cast<std::size_t>(bytes) / sizeof(glm::vec4));
    glGetNamedBufferSubData(buffer, 0, bytes, v.data());
    std::vector<glm::vec3> out;
    for (const glm::vec4& x : v) out.emplace_back(x);
    return out;
  };
  const engine::ImageRgbaF good = frame();
  ASSERT_EQ(non_finite(good), 0u);
  ASSERT_TRUE(gi_warnings.empty() && render_warnings.empty());

  const engine::Light light_before = scene.registry.get<engine::Light>(light);
  const engine::Transform light_pose = scene.registry.get<engine::Transform>(light);
  const engine::Transform crate_pose = scene.registry.get<engine::Transform>(crate);
  const engine::Transform camera_pose = scene.registry.get<engine::Transform>(camera);
  struct Case {
    const char* name;
    std::function<void()> spoil;
    int gi_skipped, render_skipped;  // entities each leaves out while spoiled
  };
  const Case cases[] = {
      {"light position NaN", [&] { scene.registry.write<engine::Transform>(light).position.x = kNaN; }, 1, 1},
      {"light 2e9 m away", [&] { scene.registry.write<engine::Transform>(light).position.y = 2e9f; }, 1, 1},
      {"light intensity +inf", [&] { scene.registry.write<engine::Light>(light).intensity = kInf; }, 1, 1},
      {"light intensity 1e30", [&] { scene.registry.write<engine::Light>(light).intensity = 1e30f; }, 1, 1},
      {"light colour NaN", [&] { scene.registry.write<engine::Light>(light).color.y = kNaN; }, 1, 1},
      {"crate position NaN", [&] { scene.registry.write<engine::Transform>(crate).position.z = kNaN; }, 1, 1},
      {"crate scale 1e30", [&] { scene.registry.write<engine::Transform>(crate).scale = glm::vec3(1e30f); }, 1, 1},
      {"crate scale 0", [&] { scene.registry.write<engine::Transform>(crate).scale = glm::vec3(0.0f); }, 1, 1},
      {"camera NaN", [&] { scene.registry.write<engine::Transform>(camera).position.x = kNaN; }, 0, 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::size_t gi_before = gi_warnings.size(), render_before = render_warnings.size();
    c.spoil();
    engine::update_world_transforms(scene.registry);
    for (int f = 0; f < 3; ++f) {
      const engine::ImageRgbaF hdr = frame();
      EXPECT_EQ(non_finite(hdr), 0u) << "frame " << f;
      EXPECT_EQ(non_finite(gltest::read_texture(gi.frame().irradiance_atlas_texture, atlas_w, atlas_h)), 0u);
      EXPECT_EQ(non_finite(crate_light()), 0u);
      EXPECT_EQ(gi.stats().skipped_entities, static_cast<std::size_t>(c.gi_skipped));
      EXPECT_EQ((*renderer)->last_skipped_entities(), c.render_skipped);
    }
    // Told once however many frames it lasts.
    EXPECT_EQ(gi_warnings.size() - gi_before, static_cast<std::size_t>(c.gi_skipped));
    EXPECT_EQ(render_warnings.size() - render_before, static_cast<std::size_t>(c.render_skipped));
    if (gi_warnings.size() > gi_before) std::printf("%s: %s\n", c.name, gi_warnings.back().c_str());
    if (render_warnings.size() > render_before) std::printf("%s: %s\n", c.name, render_warnings.back().c_str());
    // Good values again.
    scene.registry.write<engine::Light>(light) = light_before;
    scene.registry.write<engine::Transform>(light) = light_pose;
    scene.registry.write<engine::Transform>(crate) = crate_pose;
    scene.registry.write<engine::Transform>(camera) = camera_pose;
    engine::update_world_transforms(scene.registry);
    frame();  // recovered: the next case's entity is told about anew
    EXPECT_EQ(gi.stats().skipped_entities, 0u);
  }
  const engine::ImageRgbaF again = frame();
  EXPECT_EQ(gi.stats().skipped_entities, 0u);
  EXPECT_EQ((*renderer)->last_skipped_entities(), 0);
  ASSERT_EQ(again.pixels.size(), good.pixels.size());
  double diff = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < good.pixels.size(); ++i) {
    diff += std::abs(static_cast<double>(again.pixels[i]) - static_cast<double>(good.pixels[i]));
    sum += std::abs(static_cast<double>(good.pixels[i]));
  }
  EXPECT_LT(diff, 1e-4 * sum) << "the frame after recovery differs from the first";
  fs::remove_all(dir);
}

}  // namespace
