// Gameplay systems on a room built in code (demo/test_room.h): walking, mouse look,
// walls, the flashlight toggle, pushing crates, and change tracking.
#include <cmath>

#include <gtest/gtest.h>

#include <engine/components.h>

#include <game_demo/simulation.h>

#include "demo/test_room.h"

namespace {

using game_demo::InputFrame;
using game_demo::Key;
using game_demo::key_bit;

InputFrame keys(std::initializer_list<Key> held) {
  InputFrame in;
  for (Key k : held) in.keys |= key_bit(k);
  return in;
}

glm::vec3 eye_of(const game_demo::Simulation& sim) {
  return sim.registry().get<engine::Transform>(sim.context().camera).position;
}

engine::Entity only_crate(const game_demo::Simulation& sim) {
  const auto crates = sim.registry().entities_with<engine::DynamicTag>();
  EXPECT_EQ(crates.size(), 1u);
  return crates.front();
}

TEST(PlayerController, WasdMovesTheCameraAtWalkSpeed) {
  game_demo::Simulation sim(demo_test::make_room({}));
  const float step_m = 3.0f / 60.0f;  // walk speed x fixed step
  const glm::vec3 start = eye_of(sim);
  for (int i = 0; i < 10; ++i) sim.step(keys({Key::W}));
  EXPECT_NEAR(eye_of(sim).z, start.z - 10 * step_m, 1e-4f);  // forward is -Z at yaw 0
  EXPECT_NEAR(eye_of(sim).x, start.x, 1e-5f);
  for (int i = 0; i < 10; ++i) sim.step(keys({Key::D}));
  EXPECT_NEAR(eye_of(sim).x, start.x + 10 * step_m, 1e-4f);
  for (int i = 0; i < 10; ++i) sim.step(keys({Key::S}));
  EXPECT_NEAR(eye_of(sim).z, start.z, 1e-4f);
  for (int i = 0; i < 10; ++i) sim.step(keys({Key::A}));
  EXPECT_NEAR(eye_of(sim).x, start.x, 1e-4f);
  EXPECT_FLOAT_EQ(eye_of(sim).y, start.y);  // walking never changes height
}

TEST(PlayerController, MouseLookTurnsTheViewAndWalkFollowsIt) {
  game_demo::Simulation sim(demo_test::make_room({}));
  const float quarter_turn_px = (3.14159265f / 2) / 0.0025f;
  InputFrame look;
  look.mouse_dx_px = -quarter_turn_px;  // moving the mouse left turns left (towards -X)
  sim.step(look);
  const auto& pc = sim.registry().get<game_demo::PlayerController>(sim.context().camera);
  EXPECT_NEAR(pc.yaw_rad, 3.14159265f / 2, 1e-4f);
  const glm::quat q = sim.registry().get<engine::Transform>(sim.context().camera).rotation;
  const glm::vec3 view = q * glm::vec3(0, 0, -1);
  EXPECT_NEAR(view.x, -1.0f, 1e-4f);
  const glm::vec3 before = eye_of(sim);
  sim.step(keys({Key::W}));
  EXPECT_LT(eye_of(sim).x, before.x - 0.04f);
}

TEST(PlayerController, WallsKeepThePlayerInsideTheRoom) {
  game_demo::Simulation sim(demo_test::make_room({}));
  for (int i = 0; i < 5 * 60; ++i) sim.step(keys({Key::W, Key::D}));  // into the north-east corner
  const glm::vec3 eye = eye_of(sim);
  // The player box reaches 0.25 m from the eye; the inner wall faces are at x = 5, z = -3.
  EXPECT_LE(eye.x, 5.0f - 0.25f + 1e-4f);
  EXPECT_GE(eye.z, -3.0f + 0.25f - 1e-4f);
  EXPECT_GT(eye.x, 4.6f);   // it did get there, sliding along the walls
  EXPECT_LT(eye.z, -2.6f);
}

TEST(Flashlight, FTogglesTheSpotLightOnPressOnly) {
  game_demo::Simulation sim(demo_test::make_room({}));
  const engine::Entity torch = sim.context().flashlight;
  const auto& reg = sim.registry();
  const engine::Light& light = reg.get<engine::Light>(torch);
  EXPECT_EQ(light.type, engine::LightType::Spot);
  EXPECT_TRUE(light.moves);
  EXPECT_EQ(reg.get<engine::Transform>(torch).parent, sim.context().camera);
  EXPECT_FALSE(light.enabled);
  sim.step(keys({Key::F}));
  EXPECT_TRUE(reg.get<engine::Light>(torch).enabled);
  EXPECT_TRUE(reg.changed<engine::Light>(torch));
  sim.step(keys({Key::F}));  // still held: no second toggle
  EXPECT_TRUE(reg.get<engine::Light>(torch).enabled);
  EXPECT_FALSE(reg.changed<engine::Light>(torch));
  sim.step({});
  sim.step(keys({Key::F}));
  EXPECT_FALSE(reg.get<engine::Light>(torch).enabled);
}

TEST(Flashlight, FollowsTheCamera) {
  game_demo::Simulation sim(demo_test::make_room({}));
  const auto& reg = sim.registry();
  const glm::vec3 before = glm::vec3(reg.get<engine::WorldTransform>(sim.context().flashlight).matrix[3]);
  for (int i = 0; i < 20; ++i) sim.step(keys({Key::W}));
  const glm::vec3 after = glm::vec3(reg.get<engine::WorldTransform>(sim.context().flashlight).matrix[3]);
  EXPECT_NEAR(after.z - before.z, -20 * 3.0f / 60.0f, 1e-4f);
}

TEST(Push, ECratePushedForwardStopsAtTheWall) {
  // Crate 1.6 m in front of the eye, 0.6 m from the north wall (inner face z = -3).
  game_demo::Simulation sim(demo_test::make_room({{{0.0f, 0.4f, -2.0f}}}, {0.0f, 1.6f, -0.2f}));
  const engine::Entity crate = only_crate(sim);
  const auto& reg = sim.registry();
  const float z0 = reg.get<engine::Transform>(crate).position.z;
  sim.step(keys({Key::E}));
  EXPECT_LT(reg.get<engine::RigidBody>(crate).velocity_m_s.z, -1.0f);
  for (int i = 0; i < 3 * 60; ++i) sim.step({});
  const glm::vec3 p = reg.get<engine::Transform>(crate).position;
  const glm::vec3 v = reg.get<engine::RigidBody>(crate).velocity_m_s;
  EXPECT_LT(p.z, z0 - 0.4f);                           // moved forward
  EXPECT_GE(p.z - 0.4f, -3.0f - 1e-3f);                // not into the wall
  EXPECT_LT(p.z - 0.4f, -3.0f + 0.05f);                // but up against it
  EXPECT_EQ(v, glm::vec3(0.0f));                       // and at rest
  EXPECT_NEAR(p.x, 0.0f, 1e-6f);
}

TEST(Push, ACrateBeyondReachOrBehindIsNotPushed) {
  game_demo::Simulation far(demo_test::make_room({{{0.0f, 0.4f, -2.0f}}}, {0.0f, 1.6f, 2.0f}));
  far.step(keys({Key::E}));  // crate surface ~3.6 m away
  EXPECT_EQ(far.registry().get<engine::RigidBody>(only_crate(far)).velocity_m_s, glm::vec3(0.0f));
  game_demo::Simulation behind(demo_test::make_room({{{0.0f, 0.4f, 1.5f}}}, {0.0f, 1.6f, 0.0f}));
  behind.step(keys({Key::E}));  // crate 1.5 m behind the camera
  EXPECT_EQ(behind.registry().get<engine::RigidBody>(only_crate(behind)).velocity_m_s, glm::vec3(0.0f));
}

TEST(Push, ACrateStopsAgainstAnotherCrate) {
  game_demo::Simulation sim(demo_test::make_room({{{0.0f, 0.4f, -0.5f}}, {{0.0f, 0.4f, -2.0f}}}, {0.0f, 1.6f, 1.2f}));
  const auto& reg = sim.registry();
  const auto crates = reg.entities_with<engine::DynamicTag>();
  ASSERT_EQ(crates.size(), 2u);
  sim.step(keys({Key::E}));  // pushes the nearer one
  for (int i = 0; i < 3 * 60; ++i) sim.step({});
  const float front = reg.get<engine::Transform>(crates[0]).position.z;
  const float back = reg.get<engine::Transform>(crates[1]).position.z;
  EXPECT_FLOAT_EQ(back, -2.0f);                  // the far crate did not move
  EXPECT_GE(front - back, 0.8f - 1e-4f);         // boxes never overlap
  EXPECT_LT(front - back, 0.8f + 0.05f);         // and the pushed one went all the way
}

TEST(ChangeTracking, AStepWithoutInputWritesNoTransform) {
  game_demo::Simulation sim(demo_test::make_room({{{2.0f, 0.4f, -1.0f}}}));
  sim.step({});
  EXPECT_TRUE(sim.registry().changed<engine::Transform>().empty());
  EXPECT_TRUE(sim.registry().changed<engine::WorldTransform>().empty());
  EXPECT_TRUE(sim.registry().changed<engine::RigidBody>().empty());
  EXPECT_TRUE(sim.registry().changed<engine::Light>().empty());
  sim.step(keys({Key::W}));  // moving writes exactly the camera (and its child's world matrix)
  ASSERT_EQ(sim.registry().changed<engine::Transform>().size(), 1u);
  EXPECT_EQ(sim.registry().changed<engine::Transform>()[0], sim.context().camera);
  EXPECT_EQ(sim.registry().changed<engine::WorldTransform>().size(), 2u);
}

TEST(ChangeTracking, CratesAtRestAfterAPushWriteNothing) {
  game_demo::Simulation sim(demo_test::make_room({{{0.0f, 0.4f, -0.5f}}}, {0.0f, 1.6f, 1.2f}));
  sim.step(keys({Key::E}));
  sim.step({});
  EXPECT_FALSE(sim.registry().changed<engine::Transform>().empty());  // sliding
  for (int i = 0; i < 4 * 60; ++i) sim.step({});
  sim.step({});
  EXPECT_TRUE(sim.registry().changed<engine::Transform>().empty());
  EXPECT_TRUE(sim.registry().changed<engine::RigidBody>().empty());
}

TEST(SplitScreen, GTogglesOnPress) {
  game_demo::Simulation sim(demo_test::make_room({}));
  EXPECT_FALSE(sim.context().split_view);
  sim.step(keys({Key::G}));
  EXPECT_TRUE(sim.context().split_view);
  sim.step(keys({Key::G}));
  EXPECT_TRUE(sim.context().split_view);
  sim.step({});
  sim.step(keys({Key::G}));
  EXPECT_FALSE(sim.context().split_view);
}

TEST(Schedule, GameplaySystemsRunInTheDocumentedOrder) {
  game_demo::Simulation sim(demo_test::make_room({}));
  const std::vector<std::string> expected = {"player_controller", "flashlight", "split_screen",
                                             "push", "swinging_lamp", "door", "rigid_bodies", "world_transforms"};
  EXPECT_EQ(sim.schedule().order(), expected);
}

}  // namespace

namespace {

TEST(RigidBodies, UnsupportedCrateFallsToTheFloorAndStackedCrateRests) {
  // One crate floating 1 m up, one resting on another.
  game_demo::Simulation sim(demo_test::make_room(
      {{{3.0f, 1.4f, 0.0f}}, {{-3.0f, 0.4f, 0.0f}}, {{-3.0f, 1.2f, 0.0f}}}));
  const auto& reg = sim.registry();
  const auto crates = reg.entities_with<engine::DynamicTag>();
  ASSERT_EQ(crates.size(), 3u);
  sim.step({});
  EXPECT_LT(reg.get<engine::RigidBody>(crates[0]).velocity_m_s.y, 0.0f);  // falling
  EXPECT_EQ(reg.get<engine::RigidBody>(crates[2]).velocity_m_s, glm::vec3(0.0f));  // stacked: supported
  for (int i = 0; i < 2 * 60; ++i) sim.step({});
  const float bottom = reg.get<engine::Transform>(crates[0]).position.y - 0.4f;
  EXPECT_GE(bottom, -0.01f - 1e-4f);  // never more than the 1 cm collision skin into the floor
  EXPECT_LT(bottom, 0.03f + 1e-4f); // landed within the support probe
  EXPECT_EQ(reg.get<engine::RigidBody>(crates[0]).velocity_m_s, glm::vec3(0.0f));
  EXPECT_FLOAT_EQ(reg.get<engine::Transform>(crates[2]).position.y, 1.2f);
  sim.step({});
  EXPECT_TRUE(reg.changed<engine::Transform>().empty());  // everything at rest again
}

}  // namespace

namespace {

// The windowed front end polls keys once per rendered frame (2-3 frames/s on llvmpipe): a
// quick F tap between two polls is not held at either, but the key callback's press reaches
// the next step through KeyLatch and toggles the flashlight once; a second tap toggles it back.
TEST(Flashlight, ATapBetweenTwoPollsTogglesItOnce) {
  game_demo::Simulation sim(demo_test::make_room({}));
  const engine::Entity torch = sim.context().flashlight;
  game_demo::KeyLatch latch;
  const auto frame = [&](int steps) {
    for (int i = 0; i < steps; ++i) {
      sim.step(game_demo::InputFrame{.keys = latch.keys(0)});
      latch.stepped();
    }
  };
  frame(2);
  EXPECT_FALSE(sim.registry().get<engine::Light>(torch).enabled);
  latch.press(Key::F);  // pressed and released before the next poll: never held
  frame(0);             // a fast frame that ran no step keeps the press
  frame(3);
  EXPECT_TRUE(sim.registry().get<engine::Light>(torch).enabled);
  frame(3);
  EXPECT_TRUE(sim.registry().get<engine::Light>(torch).enabled);
  latch.press(Key::F);
  frame(1);
  EXPECT_FALSE(sim.registry().get<engine::Light>(torch).enabled);
  // Held keys pass through unchanged.
  EXPECT_EQ(latch.keys(game_demo::key_bit(Key::W)), game_demo::key_bit(Key::W));
}

}  // namespace
