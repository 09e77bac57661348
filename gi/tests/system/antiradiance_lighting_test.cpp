// The GI system with the corridor's door as an antiradiance region (llvmpipe): a bundle of
// light atlas + antiradiance; the atlas handed to the renderer is the baked one until the
// door moves, changes on the frame it moves, and nothing is recomputed on frames it does not.
#define GL_GLEXT_PROTOTYPES 1
#include <unistd.h>
#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "asset_scenes.h"
#include "gl_readback.h"

namespace {

namespace fs = std::filesystem;

TEST(AntiradianceLighting, TheCorridorDoorChangesTheAtlasOnlyOnFramesItMoves) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  const fs::path dir =
      fs::temp_directory_path() / ("gi_antiradiance_lighting_" + std::to_string(::getpid()) + ".gibake");
  fs::remove_all(dir);
  engine::Scene scene = gitest::asset_scene("corridor.gltf");
  gi::BakeOptions options;
  options.preset = "preview";
  options.methods = {"light_atlas", "antiradiance"};
  auto baked = gi::bake_bundle(gi::bake_input_from(scene), dir, options);
  ASSERT_TRUE(baked) << baked.error().to_string();

  auto loaded = gi::GISystem::load(dir, scene);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  EXPECT_NE(std::string(gi.label()).find("antiradiance"), std::string::npos) << gi.label();
  EXPECT_NE(gi.describe().find("antiradiance:"), std::string::npos) << gi.describe();

  GLint w = 0, h = 0;
  const std::uint32_t t0 = gi.frame().irradiance_atlas_texture.gl_name;
  ASSERT_NE(t0, 0u);
  glGetTextureLevelParameteriv(t0, 0, GL_TEXTURE_WIDTH, &w);
  glGetTextureLevelParameteriv(t0, 0, GL_TEXTURE_HEIGHT, &h);
  const std::vector<glm::vec3> before = gltest::read_texture(t0, w, h);
  EXPECT_EQ(gi.stats().antiradiance_updates, 0u);
  gi.frame();
  EXPECT_EQ(gi.stats().antiradiance_updates, 0u);
  const std::uint64_t idle = gi.stats().idle_frames;

  // Open the door to 100 degrees (authored: 50).
  const engine::Entity door = engine::find_by_name(scene.registry, "door");
  scene.registry.write<engine::Transform>(door).rotation = glm::angleAxis(glm::radians(100.0f), glm::vec3(0, 1, 0));
  engine::update_world_transforms(scene.registry);
  const std::uint32_t t1 = gi.frame().irradiance_atlas_texture.gl_name;
  EXPECT_EQ(gi.stats().antiradiance_updates, 1u);
  EXPECT_GT(gi.stats().antiradiance_relinked_elements, 0u);
  EXPECT_GT(gi.stats().last_antiradiance_ms, 0.0);
  // Solved to the residual tolerance (1e-3), not a fixed count.
  EXPECT_GT(gi.stats().antiradiance_iterations, 0);
  EXPECT_LT(gi.stats().antiradiance_residual, 1e-3);
  EXPECT_FALSE(gi.stats().antiradiance_unconverged);
  std::printf(
      "door moved: %zu elements relinked, %.1f ms (relink + direct light + GPU iteration), %d iterations, "
      "residual %.2e\n",
      gi.stats().antiradiance_relinked_elements, gi.stats().last_antiradiance_ms, gi.stats().antiradiance_iterations,
      gi.stats().antiradiance_residual);
  const std::vector<glm::vec3> after = gltest::read_texture(t1, w, h);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < after.size(); ++i) {
    ASSERT_TRUE(std::isfinite(after[i].x) && std::isfinite(after[i].y) && std::isfinite(after[i].z)) << i;
    ASSERT_GE(after[i].x, 0.0f) << i;
    if (std::abs(after[i].x - before[i].x) > 1e-4f * (1.0f + before[i].x)) ++changed;
  }
  EXPECT_GT(changed, 100u);
  EXPECT_EQ(gi.stats().idle_frames, idle);

  // Not moved again: nothing recomputed, the same atlas.
  gi.frame();
  EXPECT_EQ(gi.stats().antiradiance_updates, 1u);
  EXPECT_EQ(gi.stats().idle_frames, idle + 1);
  const std::vector<glm::vec3> again = gltest::read_texture(gi.frame().irradiance_atlas_texture, w, h);
  EXPECT_EQ(again, after);
  loaded->reset();
  fs::remove_all(dir);
}

}  // namespace
