// The sky visibility of dynamic entities (system/sky_visibility.h), which the renderer's sky
// term uses on them: a crate on an open floor sees all the sky above and none below; under
// a roof it sees only the sky near the horizon; it is measured again only when it moves; and
// GISystem hands it to the renderer for a sky-lit scene.
#include "system/sky_visibility.h"

#include <unistd.h>
#include <gtest/gtest.h>
#include <engine/components.h>
#include <engine/gpu/context.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>

#include <cstdio>
#include <filesystem>

namespace {

engine::Primitive quad(glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  engine::Primitive p;
  const glm::vec3 n = glm::normalize(glm::cross(u, v));
  p.positions = {c - u - v, c + u - v, c + u + v, c - u + v};
  p.normals.assign(4, n);
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

// A 40 x 40 m static floor (and optionally a roof as large at 2 m), a dynamic 0.5 m crate on it.
engine::Scene crate_scene(bool roof) {
  engine::SceneAsset a;
  a.meshes.push_back({.name = "floor", .primitives = {quad({0, 0, 0}, {0, 0, 20}, {20, 0, 0})}});
  engine::Mesh crate{.name = "crate"};
  const float h = 0.25f;
  crate.primitives.push_back(quad({0, 2 * h, 0}, {0, 0, h}, {h, 0, 0}));
  crate.primitives.push_back(quad({h, h, 0}, {0, h, 0}, {0, 0, h}));
  a.meshes.push_back(crate);
  const auto node = [&](const char* name, int mesh, engine::Mobility m) {
    engine::Node n;
    n.name = name;
    n.mesh = mesh;
    n.gi.mobility = m;
    a.nodes.push_back(n);
  };
  node("floor", 0, engine::Mobility::Static);
  node("crate", 1, engine::Mobility::Dynamic);
  if (roof) {
    a.meshes.push_back({.name = "roof", .primitives = {quad({0, 2, 0}, {20, 0, 0}, {0, 0, 20})}});  // faces down
    node("roof", 2, engine::Mobility::Static);
  }
  a.environment.sky_radiance = glm::vec3(1.0f);
  return engine::instantiate(std::move(a));
}

enum Axis { kPosX, kNegX, kPosY, kNegY, kPosZ, kNegZ };

}  // namespace

TEST(SkyVisibility, CrateOnAnOpenFloorAndUnderARoof) {
  engine::Scene open = crate_scene(false);
  auto sky = gi::SkyVisibility::create(open);
  ASSERT_TRUE(sky) << sky.error().to_string();
  EXPECT_EQ((*sky)->update(), 1u);
  const engine::Entity crate = engine::find_by_name(open.registry, "crate");
  float v[6] = {};
  ASSERT_TRUE((*sky)->get(crate, v));
  std::printf("open floor: +X %.3f -X %.3f +Y %.3f -Y %.3f +Z %.3f -Z %.3f\n", double{v[0]}, double{v[1]}, double{v[2]},
              double{v[3]}, double{v[4]}, double{v[5]});
  EXPECT_FLOAT_EQ(v[kPosY], 1.0f) << "nothing above";
  EXPECT_NEAR(v[kNegY], 0.0f, 0.01f) << "the floor below (but for a grazing direction past its edge)";
  for (Axis a : {kPosX, kNegX, kPosZ, kNegZ}) EXPECT_NEAR(v[a], 0.5f, 0.05f) << "a side: the upper half of its sky";
  EXPECT_EQ((*sky)->update(), 0u) << "nothing moved";

  open.registry.write<engine::WorldTransform>(crate).matrix[3] = glm::vec4(3.0f, 0.0f, 1.0f, 1.0f);
  EXPECT_EQ((*sky)->update(), 1u) << "the crate moved";

  engine::Scene covered = crate_scene(true);
  auto under = gi::SkyVisibility::create(covered);
  ASSERT_TRUE(under) << under.error().to_string();
  (*under)->update();
  float w[6] = {};
  ASSERT_TRUE((*under)->get(engine::find_by_name(covered.registry, "crate"), w));
  std::printf("under a roof at 2 m (20 m each way): +X %.3f +Y %.3f\n", double{w[kPosX]}, double{w[kPosY]});
  // Only the strip within atan(1.75 / 20) = 5 degrees of the horizon escapes: sin^2(5 deg) = 0.008.
  EXPECT_LT(w[kPosY], 0.03f) << "the roof hides the sky above";
  EXPECT_LT(w[kPosX], 0.2f);
  EXPECT_FALSE((*under)->get(engine::find_by_name(covered.registry, "floor"), w)) << "static entities are not measured";
}

// GISystem of a sky-lit scene hands the renderer the crate's measured visibility.
TEST(SkyVisibility, GiSystemProvidesItForASkyLitScene) {
  engine::Scene scene = crate_scene(true);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("gi_sky_visibility_" + std::to_string(::getpid()) + ".gibake");
  std::filesystem::remove_all(dir);
  auto baked = gi::bake_bundle(gi::bake_input_from(scene), dir,
                               {.preset = "preview", .methods = {"light_atlas"}, .texels_per_metre = 1.0f});
  ASSERT_TRUE(baked) << baked.error().to_string();
  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  auto system = gi::GISystem::load(dir, scene);
  ASSERT_TRUE(system) << system.error().to_string();
  const engine::IndirectLightFrame& f = (*system)->frame();
  float v[6] = {};
  ASSERT_TRUE(f.sky_visibility(engine::find_by_name(scene.registry, "crate"), v));
  EXPECT_LT(v[kPosY], 0.03f);
  EXPECT_FALSE(f.sky_visibility(engine::find_by_name(scene.registry, "floor"), v));
  system->reset();
  std::filesystem::remove_all(dir);
}
