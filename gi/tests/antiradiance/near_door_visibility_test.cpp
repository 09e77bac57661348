// Explicit visibility near the door (antiradiance/near_door_visibility.h) on the door scene:
// the receivers around the door gather with ray-traced visibility (the shut door lets
// nothing through to the receiver plate behind the wall), the other leaves keep the region's
// antiradiance solve exactly, and a move back to the baked pose returns to the baseline.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "antiradiance/near_door_visibility.h"
#include "antiradiance_scenes.h"

namespace {

TEST(NearDoorVisibility, TheShutDoorBlocksTheReceiverAndTheOthersKeepTheRegionsSolve) {
  const artest::DoorScene scene = artest::door_scene(90.0f);
  gi::AntiradianceSettings s;
  s.patch_size_m = 0.5f;
  s.bins_per_side = 8;
  s.iterations = 8;
  auto region = gi::AntiradianceRegion::create(scene.input, s);
  ASSERT_TRUE(region) << region.error().to_string();
  region->update(false);
  gi::NearDoorVisibilitySettings ns;
  ns.radius_m = 0.25f;  // the door reaches 1.12 m from its hinge, the receiver plate 1.3 m
  auto near = gi::NearDoorVisibility::create(scene.input, *region, scene.door, ns);
  ASSERT_TRUE(near) << near.error().to_string();
  const std::size_t leaves = region->hierarchy().leaf_count();
  EXPECT_GT(near->receivers(), 0u);
  EXPECT_LT(near->receivers(), leaves);
  const glm::vec3 open = artest::instance_mean(region->hierarchy(), scene.input, scene.receiver, near->baseline());

  const glm::mat4 shut = artest::hinge_matrix(0.0f);
  region->set_instance_transform(scene.door, shut);
  region->update();
  const std::vector<glm::vec3> e = near->move(*region, scene.door, shut);
  const std::vector<glm::vec3> others = region->irradiance();
  ASSERT_EQ(e.size(), leaves);
  std::size_t held = 0;
  for (std::size_t l = 0; l < leaves; ++l)
    if (e[l] == others[l]) ++held;
  EXPECT_GE(held, leaves - near->receivers());  // every other leaf is the region's, bit for bit
  const glm::vec3 closed = artest::instance_mean(region->hierarchy(), scene.input, scene.receiver, e);
  std::printf("receiver: open %.5f, shut %.6f W/m^2 (near visibility, %zu of %zu leaves), %d iterations\n",
              static_cast<double>(open.x), static_cast<double>(closed.x), near->receivers(), leaves,
              near->last_iterations());
  EXPECT_GT(open.x, 0.05f);
  EXPECT_LT(closed.x, 0.01f * open.x);

  const glm::mat4 baked = artest::hinge_matrix(90.0f);
  region->set_instance_transform(scene.door, baked);
  region->update();
  const std::vector<glm::vec3> back = near->move(*region, scene.door, baked);
  const glm::vec3 again = artest::instance_mean(region->hierarchy(), scene.input, scene.receiver, back);
  EXPECT_NEAR(again.x, open.x, 2e-3f * open.x);
}

}  // namespace
