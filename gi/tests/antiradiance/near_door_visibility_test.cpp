// Explicit visibility near the door (antiradiance/near_door_visibility.h) on the door scene:
// the receivers around the door gather with ray-traced visibility (the shut door lets
// nothing through to the receiver plate behind the wall), the other leaves keep the region's
// antiradiance solve exactly, and a move back to the baked pose returns to the baseline.
#include <gtest/gtest.h>

#include <algorithm>
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

// The near set's budget (issue 37: the light beyond a shut door comes over several bounces, so
// the set reaches beyond the radius as far as its memory allows): beyond the radius set, the
// leaves nearest the door come first, the rows fit the budget, a budget below the radius set
// keeps the radius set, and a large one takes every leaf.
TEST(NearDoorVisibility, BeyondTheRadiusTheBudgetTakesTheLeavesNearestTheDoorFirst) {
  const artest::DoorScene scene = artest::door_scene(90.0f);
  gi::AntiradianceSettings s;
  s.patch_size_m = 0.5f;
  s.bins_per_side = 8;
  auto region = gi::AntiradianceRegion::create(scene.input, s);
  ASSERT_TRUE(region) << region.error().to_string();
  region->update(false);
  const gi::ElementHierarchy& h = region->hierarchy();
  const std::size_t leaves = h.leaf_count();
  gi::NearDoorVisibilitySettings ns;
  ns.radius_m = 0.25f;
  ns.point_pairs = 4;
  auto count = [](const std::vector<char>& m) {
    return static_cast<std::size_t>(std::count(m.begin(), m.end(), char{1}));
  };
  const std::vector<char> radius = gi::near_door_receivers(scene.input, h, scene.door, ns);
  const std::size_t r = count(radius);
  ASSERT_GT(r, 0u);
  ASSERT_LT(r + 5, leaves);
  const std::size_t row = leaves * gi::ExactLeafTransport::row_bytes_per_leaf(ns.point_pairs);
  EXPECT_EQ(row, leaves * 6u);  // a float coupling and one 16-bit word of visibility per leaf

  ns.budget_bytes = (r + 5) * row + row / 2;  // room for five more rows, not six
  const std::vector<char> more = gi::near_door_receivers(scene.input, h, scene.door, ns);
  EXPECT_EQ(count(more), r + 5);
  const glm::vec3 hinge(scene.input.instances[scene.door].object_to_world[3]);
  auto gap = [&](std::size_t l) {
    const gi::ElementNode& e = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    return glm::length(e.center - hinge) - e.radius_m;
  };
  float farthest_added = 0.0f, nearest_left = 1e30f;
  for (std::size_t l = 0; l < leaves; ++l) {
    if (radius[l]) {
      EXPECT_TRUE(more[l]) << "leaf " << l << " of the radius set left out";
    }
    if (more[l] && !radius[l]) farthest_added = std::max(farthest_added, gap(l));
    if (!more[l]) nearest_left = std::min(nearest_left, gap(l));
  }
  EXPECT_LE(farthest_added, nearest_left);

  ns.budget_bytes = row;  // below the radius set: the radius set
  EXPECT_EQ(gi::near_door_receivers(scene.input, h, scene.door, ns), radius);
  ns.budget_bytes = 0;  // off: the radius set
  EXPECT_EQ(gi::near_door_receivers(scene.input, h, scene.door, ns), radius);
  ns.budget_bytes = std::size_t{1} << 40;  // everything
  EXPECT_EQ(count(gi::near_door_receivers(scene.input, h, scene.door, ns)), leaves);
  // A door the input does not hold: no receiver (no read past the instances).
  EXPECT_EQ(
      count(gi::near_door_receivers(scene.input, h, static_cast<std::uint32_t>(scene.input.instances.size()), ns)), 0u);

  // The class takes the same set, and its rows fit the budget.
  ns.budget_bytes = (r + 5) * row + row / 2;
  auto near = gi::NearDoorVisibility::create(scene.input, *region, scene.door, ns);
  ASSERT_TRUE(near) << near.error().to_string();
  EXPECT_EQ(near->receiver_mask(), more);
  EXPECT_EQ(near->receivers(), r + 5);
  EXPECT_LE(near->table_bytes(), ns.budget_bytes);
  EXPECT_EQ(near->table_bytes(), (r + 5) * row);
}

}  // namespace
