// Near-door visibility in the runtime (issue 37; AntiradianceLighting with the bake's
// near_visibility) on the corridor, llvmpipe: the bake goes through antiradiance.bin (the
// element triangles the rays need come back from the file) and the door shuts. The receivers
// that lose at least half their light in truth (every leaf pair with ray-traced visibility)
// lose some of it in the runtime, where antiradiance alone takes none away; the runtime's
// change at the receivers is exactly the class's own move output for the same pose (the
// wiring adds nothing); back at the baked pose it is 0. A bake without the triangles falls
// back, visibly, to antiradiance alone.
#include <unistd.h>
#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/scene.h>
#include <gi/bake.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "antiradiance/antiradiance_exact_transport.h"
#include "antiradiance/antiradiance_io.h"
#include "antiradiance/near_door_visibility.h"
#include "asset_scenes.h"
#include "gl_context.h"
#include "system/antiradiance_lighting.h"
#include "uv/atlas_layout.h"

namespace {

namespace fs = std::filesystem;

// Each GPU test's start: the GL context, the corridor, its bake input and a 10 texels/m
// static layout (built in place: the input refers to the scene).
struct CorridorRun {
  engine::GpuContext ctx = gltest::headless_or_fail();
  engine::Scene scene = gitest::asset_scene("corridor.gltf");
  gi::BakeInput input = gi::bake_input_from(scene);
  gi::AtlasLayout layout = gi::static_world_layout(input, 10.0f).value();
};

// The preview preset (64 bins: the cheapest region) with near visibility on, saved and loaded
// as a bundle would carry it.
gi::AntiradianceBake near_bake(const gi::BakeInput& input, const std::string& name, std::uint64_t budget_bytes = 0) {
  gi::AntiradianceSettings s = gi::antiradiance_preset("preview");
  s.near_visibility = true;
  s.near_visibility_budget_bytes = budget_bytes;
  auto bake = gi::bake_antiradiance(input, s);
  EXPECT_TRUE(bake) << bake.error().to_string();
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "antiradiance_near_visibility" / name;
  fs::remove_all(dir);
  EXPECT_TRUE(gi::save_antiradiance(dir, *bake, input));
  auto loaded = gi::load_antiradiance(dir, input);
  EXPECT_TRUE(loaded) << loaded.error().to_string();
  return std::move(loaded).value();
}

void set_door(engine::Scene& scene, float degrees) {
  const engine::Entity door = engine::find_by_name(scene.registry, "door");
  scene.registry.write<engine::Transform>(door).rotation = glm::angleAxis(glm::radians(degrees), glm::vec3(0, 1, 0));
  engine::update_world_transforms(scene.registry);
}

// The true indirect light per leaf at the region's current pose: every leaf pair's form factor
// with ray-traced visibility (ExactLeafTransport, all leaves), its own direct light as source.
std::vector<glm::vec3> exact_light(const gi::BakeInput& input, const gi::AntiradianceRegion& region, std::uint32_t door,
                                   const glm::mat4& pose) {
  gi::ExactTransportSettings es;
  es.point_pairs = 4;
  auto t = gi::ExactLeafTransport::create(input, es);
  EXPECT_TRUE(t) << t.error().to_string();
  t->set_instance_transform(door, pose);
  t->update(region.hierarchy());
  return t->solve(region.hierarchy(), region.direct()).irradiance;
}

TEST(AntiradianceNearVisibility, TheShutDoorTakesTheLightItLetInAndTheWiringAddsNothing) {
  CorridorRun run;
  engine::Scene& scene = run.scene;
  const gi::BakeInput& input = run.input;
  gi::AntiradianceBake bake = near_bake(input, "runtime");
  auto region = gi::AntiradianceRegion::create(input, gi::AntiradianceBake(bake));  // the class's own run
  ASSERT_TRUE(region) << region.error().to_string();
  auto made = gi::AntiradianceLighting::create(std::move(bake), input, run.layout, scene.registry);
  ASSERT_TRUE(made) << made.error().to_string();
  gi::AntiradianceLighting& a = **made;
  ASSERT_TRUE(a.stats().near_visibility) << a.near_fell_back_reason();
  EXPECT_FALSE(a.stats().near_fell_back);
  EXPECT_GT(a.stats().near_receivers, 0u);
  const std::uint32_t door = region->hierarchy().deforming_instances[0];
  const engine::Entity door_entity = engine::find_by_name(scene.registry, "door");
  const glm::mat4 baked = scene.registry.get<engine::WorldTransform>(door_entity).matrix;
  const glm::quat authored = scene.registry.get<engine::Transform>(door_entity).rotation;
  const std::vector<glm::vec3> true_open = exact_light(input, *region, door, baked);

  // Shut (authored: 50 degrees open).
  set_door(scene, 0.0f);
  ASSERT_TRUE(a.update()) << a.disabled();
  const gi::AntiradianceLighting::Stats st = a.stats();
  std::printf("door shut: %zu receivers, near %.1f ms of %.1f ms, %zu rays, %zu pairs, %d iterations\n",
              st.near_receivers, st.near_ms, st.last_ms, st.near_rays, st.near_pairs, st.near_iterations);
  EXPECT_GT(st.near_ms, 0.0);
  EXPECT_GT(st.near_rays, 0u);
  EXPECT_GT(st.near_iterations, 0);

  // The class on its own, at the same pose, holding the other leaves at the same GPU solve.
  gi::NearDoorVisibilitySettings ns;
  ns.radius_m = region->settings().near_visibility_radius_m;
  ns.point_pairs = region->settings().near_visibility_point_pairs;
  auto near = gi::NearDoorVisibility::create(input, *region, door, ns);
  ASSERT_TRUE(near) << near.error().to_string();
  EXPECT_EQ(near->receivers(), st.near_receivers);
  const glm::mat4 shut = scene.registry.get<engine::WorldTransform>(door_entity).matrix;
  region->set_instance_transform(door, shut);
  region->update(false);
  const std::vector<glm::vec3> true_shut = exact_light(input, *region, door, shut);
  region->adopt_irradiance(a.solved_irradiance());
  const std::vector<glm::vec3> e = near->move(*region, door, shut);
  const std::vector<glm::vec3>& change = a.leaf_change();
  const std::vector<glm::vec3>& solved = a.solved_irradiance();
  const std::vector<glm::vec3>& base = region->baseline();
  ASSERT_EQ(change.size(), e.size());
  const gi::ElementHierarchy& h = region->hierarchy();
  std::size_t receivers = 0, dark = 0;
  double lost = 0.0, near_lost = 0.0, alone_lost = 0.0;
  for (std::size_t l = 0; l < e.size(); ++l) {
    const bool receiver = e[l] != solved[l] || near->baseline()[l] != base[l];
    if (!receiver) {
      EXPECT_EQ(change[l], solved[l] - base[l]) << "leaf " << l << " keeps the GPU solve's change";
      continue;
    }
    ++receivers;
    ASSERT_EQ(change[l], e[l] - near->baseline()[l]) << "leaf " << l << ": the runtime's change is the class's";
    // The receivers beyond the door: they lose at least half their light when it shuts (truth).
    const double open = true_open[l].x, loss = open - static_cast<double>(true_shut[l].x);
    if (!(open > 0.0) || loss < 0.5 * open) continue;
    const auto area = static_cast<double>(h.nodes[static_cast<std::size_t>(h.leaves[l])].area_m2);
    ++dark;
    lost += area * loss;
    near_lost -= area * static_cast<double>(change[l].x);
    alone_lost -= area * static_cast<double>(solved[l].x - base[l].x);
  }
  std::printf(
      "%zu of %zu receivers lose half their light or more (truth): they lose %.4f W, the runtime %.4f W "
      "with near visibility, %.4f W with antiradiance alone\n",
      dark, receivers, lost, near_lost, alone_lost);
  EXPECT_LE(receivers, st.near_receivers);
  ASSERT_GT(dark, 0u);
  // Measured (preview region, 4 point pairs, the 1 m radius alone): the runtime takes 0.375 of
  // the true loss away with near visibility (0.197 of 0.526 W), antiradiance alone -0.04 (it
  // adds light). The leaves beyond the radius stay at antiradiance's solve, which hardly
  // darkens: the medium budget's larger set (next test) is what takes the rest. (0.072 of 2.68
  // W before touching leaves took Lambert's form factor: the truth's own estimator was
  // inflated; docs/antiradiance.md "A near set as large as its budget".) Checked: at least
  // 0.04 of the loss, and 4x antiradiance alone's.
  EXPECT_GT(near_lost, 0.04 * lost);
  EXPECT_GT(near_lost, 4.0 * std::max(alone_lost, 0.01 * lost));

  // Back at the baked pose (the authored rotation, bit for bit): the change is 0 everywhere.
  scene.registry.write<engine::Transform>(door_entity).rotation = authored;
  engine::update_world_transforms(scene.registry);
  ASSERT_TRUE(a.update());
  for (const glm::vec3& c : a.leaf_change()) ASSERT_EQ(c, glm::vec3(0.0f));
  EXPECT_EQ(a.stats().near_ms, 0.0);
}

// The medium preset's budget (64 MiB) makes every corridor leaf a receiver: shutting the door
// then takes, leaf by leaf, the share of its light the truth says it loses (every leaf pair
// with ray-traced visibility), which is what the composite applies to the atlas
// (composite_change: a loss as a share of the leaf's own light). Per leaf, not only in total.
TEST(AntiradianceNearVisibility, WithTheMediumBudgetEveryLeafLosesTheShareOfLightTheTruthLoses) {
  CorridorRun run;
  engine::Scene& scene = run.scene;
  const gi::BakeInput& input = run.input;
  const std::uint64_t budget = gi::antiradiance_preset("medium").near_visibility_budget_bytes;
  gi::AntiradianceBake bake = near_bake(input, "budget", budget);
  auto region = gi::AntiradianceRegion::create(input, gi::AntiradianceBake(bake));
  ASSERT_TRUE(region) << region.error().to_string();
  auto made = gi::AntiradianceLighting::create(std::move(bake), input, run.layout, scene.registry);
  ASSERT_TRUE(made) << made.error().to_string();
  gi::AntiradianceLighting& a = **made;
  const gi::ElementHierarchy& h = region->hierarchy();
  ASSERT_EQ(a.stats().near_receivers, h.leaf_count()) << "the budget holds every corridor leaf";
  EXPECT_LE(a.stats().near_table_bytes, budget);
  const std::uint32_t door = h.deforming_instances[0];
  const engine::Entity door_entity = engine::find_by_name(scene.registry, "door");
  const std::vector<glm::vec3> true_open =
      exact_light(input, *region, door, scene.registry.get<engine::WorldTransform>(door_entity).matrix);
  const std::vector<glm::vec4> zero = a.leaf_baseline();
  for (const glm::vec4& z : zero) ASSERT_EQ(z.w, 1.0f) << "every leaf a receiver: its loss taken as a share";
  set_door(scene, 0.0f);
  ASSERT_TRUE(a.update()) << a.disabled();
  const glm::mat4 shut = scene.registry.get<engine::WorldTransform>(door_entity).matrix;
  region->set_instance_transform(door, shut);
  region->update(false);
  const std::vector<glm::vec3> true_shut = exact_light(input, *region, door, shut);
  const std::vector<glm::vec3>& change = a.leaf_change();
  // The leaves the door's shutting darkens by half or more in truth (the corridor beyond it,
  // the door's far side), and the share each keeps, runtime against truth.
  std::size_t dark = 0, within = 0;
  double kept_runtime = 0.0, kept_truth = 0.0, area_sum = 0.0, worst = 0.0;
  for (std::size_t l = 0; l < change.size(); ++l) {
    const double open = true_open[l].x;
    if (!(open > 0.0) || true_shut[l].x > 0.5f * true_open[l].x || !(zero[l].x > 0.0f)) continue;
    const double truth = static_cast<double>(true_shut[l].x) / open;
    const double runtime = std::clamp(1.0 + static_cast<double>(change[l].x / zero[l].x), 0.0, 1.0);
    const auto area = static_cast<double>(h.nodes[static_cast<std::size_t>(h.leaves[l])].area_m2);
    ++dark;
    if (std::abs(runtime - truth) <= 0.1) ++within;
    worst = std::max(worst, std::abs(runtime - truth));
    kept_runtime += area * runtime;
    kept_truth += area * truth;
    area_sum += area;
  }
  std::printf(
      "%zu of %zu leaves lose half their light or more (truth): they keep %.4f of it in truth, %.4f in the runtime "
      "(area-weighted); %zu within 0.1 of the truth's share, the worst %.3f off\n",
      dark, change.size(), kept_truth / area_sum, kept_runtime / area_sum, within, worst);
  // Measured: 1168 leaves keep 0.047 in truth, 0.060 in the runtime, every one within 0.1 (the
  // worst 0.036 off). With the solve stopped on the sum of |dE| alone the runtime kept 0.17
  // (its warm start from the open door's light was left a fifth in the corridor), with a
  // 1% per-leaf tolerance 0.11.
  ASSERT_GT(dark, 200u);
  EXPECT_NEAR(kept_runtime / area_sum, kept_truth / area_sum, 0.025);
  EXPECT_EQ(within, dark);
  EXPECT_LT(worst, 0.06);
}

TEST(AntiradianceNearVisibility, ABakeWithoutTheTrianglesFallsBackVisiblyToAntiradianceAlone) {
  CorridorRun run;
  engine::Scene& scene = run.scene;
  const gi::BakeInput& input = run.input;
  gi::AntiradianceBake bake = near_bake(input, "fallback");
  bake.hierarchy.corners.clear();  // as a region made without them
  bake.hierarchy.object_corners.clear();
  std::string warning;
  auto made = gi::AntiradianceLighting::create(std::move(bake), input, run.layout, scene.registry,
                                               [&](gi::LogLevel level, std::string_view message) {
                                                 if (level == gi::LogLevel::Warning) warning = std::string(message);
                                               });
  ASSERT_TRUE(made) << made.error().to_string();
  gi::AntiradianceLighting& a = **made;
  EXPECT_FALSE(a.stats().near_visibility);
  EXPECT_TRUE(a.stats().near_fell_back);
  EXPECT_NE(a.near_fell_back_reason().find("triangles"), std::string::npos) << a.near_fell_back_reason();
  EXPECT_NE(warning.find("near-door visibility off"), std::string::npos) << warning;
  set_door(scene, 0.0f);
  ASSERT_TRUE(a.update()) << a.disabled();
  EXPECT_EQ(a.stats().near_ms, 0.0);
  EXPECT_EQ(a.stats().near_rays, 0u);
  EXPECT_FALSE(a.leaf_change().empty());
}

}  // namespace
