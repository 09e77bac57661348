#include <engine/components.h>
#include <engine/scene.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

namespace {

glm::vec3 origin_of(const glm::mat4& m) { return glm::vec3(m[3]); }

TEST(WorldTransforms, ChildFollowsParentChain) {
  engine::Registry reg;
  const engine::Entity root = reg.create();
  const engine::Entity child = reg.create();
  const engine::Entity grandchild = reg.create();
  reg.emplace<engine::Transform>(root, engine::Transform{.position = {1, 0, 0}});
  engine::Transform ct;
  ct.position = {0, 2, 0};
  ct.rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
  ct.parent = root;
  reg.emplace<engine::Transform>(child, ct);
  reg.emplace<engine::Transform>(grandchild, engine::Transform{.position = {1, 0, 0}, .parent = child});
  engine::update_world_transforms(reg);
  const glm::vec3 p = origin_of(reg.get<engine::WorldTransform>(grandchild).matrix);
  // child's +X is world +Y after the 90 degree roll: (1,0,0) + (0,2,0) + (0,1,0)
  EXPECT_NEAR(p.x, 1.0f, 1e-5f);
  EXPECT_NEAR(p.y, 3.0f, 1e-5f);
  EXPECT_NEAR(p.z, 0.0f, 1e-5f);
}

TEST(WorldTransforms, OnlyMovedSubtreeIsMarkedChanged) {
  engine::Registry reg;
  const engine::Entity a = reg.create();
  const engine::Entity a_child = reg.create();
  const engine::Entity b = reg.create();
  reg.emplace<engine::Transform>(a);
  reg.emplace<engine::Transform>(a_child, engine::Transform{.position = {0, 1, 0}, .parent = a});
  reg.emplace<engine::Transform>(b, engine::Transform{.position = {5, 0, 0}});
  engine::update_world_transforms(reg);
  reg.begin_frame();

  engine::update_world_transforms(reg);  // nothing written: nothing moves
  EXPECT_TRUE(reg.changed<engine::WorldTransform>().empty());

  reg.write<engine::Transform>(a).position.z = 3.0f;
  engine::update_world_transforms(reg);
  EXPECT_TRUE(reg.changed<engine::WorldTransform>(a));
  EXPECT_TRUE(reg.changed<engine::WorldTransform>(a_child));
  EXPECT_FALSE(reg.changed<engine::WorldTransform>(b));
  EXPECT_NEAR(origin_of(reg.get<engine::WorldTransform>(a_child).matrix).z, 3.0f, 1e-6f);
}

TEST(WorldTransforms, WriteWithSameValueDoesNotReportMotion) {
  engine::Registry reg;
  const engine::Entity a = reg.create();
  reg.emplace<engine::Transform>(a, engine::Transform{.position = {1, 2, 3}});
  engine::update_world_transforms(reg);
  reg.begin_frame();
  reg.write<engine::Transform>(a).position = {1, 2, 3};
  engine::update_world_transforms(reg);
  EXPECT_TRUE(reg.changed<engine::Transform>(a));
  EXPECT_FALSE(reg.changed<engine::WorldTransform>(a));
}

TEST(WorldTransforms, DestroyedParentLeavesChildInWorldSpace) {
  engine::Registry reg;
  const engine::Entity parent = reg.create();
  const engine::Entity child = reg.create();
  reg.emplace<engine::Transform>(parent, engine::Transform{.position = {10, 0, 0}});
  reg.emplace<engine::Transform>(child, engine::Transform{.position = {1, 0, 0}, .parent = parent});
  engine::update_world_transforms(reg);
  reg.destroy(parent);
  reg.write<engine::Transform>(child);  // re-evaluate
  engine::update_world_transforms(reg);
  EXPECT_NEAR(origin_of(reg.get<engine::WorldTransform>(child).matrix).x, 1.0f, 1e-6f);
}

}  // namespace
