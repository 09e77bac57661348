#include <engine/scene.h>

#include <gtest/gtest.h>

namespace {

engine::SceneAsset two_level_asset() {
  engine::SceneAsset a;
  a.meshes.push_back(engine::Mesh{"box", {}});
  a.lights.push_back(engine::NamedLight{"lamp", engine::Light{.type = engine::LightType::Spot, .moves = true}});
  a.cameras.push_back(engine::NamedCamera{"cam", engine::Camera{}});
  engine::Node root{.name = "root", .translation = {0, 1, 0}};
  engine::Node crate{.name = "crate", .parent = 0, .translation = {2, 0, 0}, .mesh = 0};
  crate.gi.mobility = engine::Mobility::Dynamic;
  engine::Node wall{.name = "wall", .mesh = 0};
  engine::Node lamp{.name = "lamp", .parent = 0, .light = 0};
  engine::Node cam{.name = "camera", .camera = 0};
  a.nodes = {root, crate, wall, lamp, cam};
  return a;
}

TEST(Instantiate, NodesBecomeEntitiesWithTheirComponents) {
  engine::Scene scene = engine::instantiate(two_level_asset());
  const engine::Registry& reg = scene.registry;
  ASSERT_EQ(scene.node_entities.size(), 5u);
  EXPECT_EQ(reg.alive(), 5u);
  const engine::Entity crate = engine::find_by_name(reg, "crate");
  const engine::Entity wall = engine::find_by_name(reg, "wall");
  ASSERT_TRUE(crate);
  EXPECT_TRUE(reg.has<engine::DynamicTag>(crate));
  EXPECT_TRUE(reg.has<engine::RigidBody>(crate));
  EXPECT_FALSE(reg.has<engine::StaticTag>(crate));
  EXPECT_TRUE(reg.has<engine::StaticTag>(wall));  // unflagged meshes are static
  EXPECT_EQ(reg.get<engine::Transform>(crate).parent, scene.node_entities[0]);
  EXPECT_NEAR(reg.get<engine::WorldTransform>(crate).matrix[3].y, 1.0f, 1e-6f);
  const engine::Entity lamp = engine::find_by_name(reg, "lamp");
  EXPECT_TRUE(reg.get<engine::Light>(lamp).moves);
  EXPECT_EQ(engine::find_camera(reg), engine::find_by_name(reg, "camera"));
}

}  // namespace
