// Gameplay systems on a room built in code (demo/test_room.h): walking, mouse look,
// walls, the flashlight toggle, pushing crates, change tracking, flying and the starting view.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

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
  EXPECT_GT(eye.x, 4.6f);  // it did get there, sliding along the walls
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
  EXPECT_LT(p.z, z0 - 0.4f);             // moved forward
  EXPECT_GE(p.z - 0.4f, -3.0f - 1e-3f);  // not into the wall
  EXPECT_LT(p.z - 0.4f, -3.0f + 0.05f);  // but up against it
  EXPECT_EQ(v, glm::vec3(0.0f));         // and at rest
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
  EXPECT_FLOAT_EQ(back, -2.0f);           // the far crate did not move
  EXPECT_GE(front - back, 0.8f - 1e-4f);  // boxes never overlap
  EXPECT_LT(front - back, 0.8f + 0.05f);  // and the pushed one went all the way
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
  const std::vector<std::string> expected = {"player_controller", "flashlight", "split_screen", "push",
                                             "swinging_lamp",     "door",       "rigid_bodies", "world_transforms"};
  EXPECT_EQ(sim.schedule().order(), expected);
}

}  // namespace

namespace {

TEST(RigidBodies, UnsupportedCrateFallsToTheFloorAndStackedCrateRests) {
  // One crate floating 1 m up, one resting on another.
  game_demo::Simulation sim(demo_test::make_room({{{3.0f, 1.4f, 0.0f}}, {{-3.0f, 0.4f, 0.0f}}, {{-3.0f, 1.2f, 0.0f}}}));
  const auto& reg = sim.registry();
  const auto crates = reg.entities_with<engine::DynamicTag>();
  ASSERT_EQ(crates.size(), 3u);
  sim.step({});
  EXPECT_LT(reg.get<engine::RigidBody>(crates[0]).velocity_m_s.y, 0.0f);           // falling
  EXPECT_EQ(reg.get<engine::RigidBody>(crates[2]).velocity_m_s, glm::vec3(0.0f));  // stacked: supported
  for (int i = 0; i < 2 * 60; ++i) sim.step({});
  const float bottom = reg.get<engine::Transform>(crates[0]).position.y - 0.4f;
  EXPECT_GE(bottom, -0.01f - 1e-4f);  // never more than the 1 cm collision skin into the floor
  EXPECT_LT(bottom, 0.03f + 1e-4f);   // landed within the support probe
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

namespace {

game_demo::SimulationSettings flying() {
  game_demo::SimulationSettings s;
  s.tuning.locomotion = game_demo::Locomotion::Fly;
  return s;
}

// The room's meshes span x -5.2..5.2, y -0.2..3.2, z -3.2..3.2 (demo/test_room.h).
const float kRoomDiagonalM = std::sqrt(10.4f * 10.4f + 3.4f * 3.4f + 6.4f * 6.4f);

TEST(Locomotion, WalkOnTheDemoLevelFlyElsewhere) {
  EXPECT_EQ(game_demo::default_locomotion(""), game_demo::Locomotion::Walk);
  EXPECT_EQ(game_demo::default_locomotion("assets/demo_level.gltf"), game_demo::Locomotion::Walk);
  EXPECT_EQ(game_demo::default_locomotion("/x/demo_level.draco.glb"), game_demo::Locomotion::Walk);
  EXPECT_EQ(game_demo::default_locomotion("../shared/external-assets/dabrovic-sponza/sponza.gltf"),
            game_demo::Locomotion::Fly);
  EXPECT_EQ(game_demo::SimulationSettings{}.tuning.locomotion, game_demo::Locomotion::Walk);
}

// Flying: W along the view with its pitch, Up/Down along +Y, through walls, at the scene's
// diagonal / fly_crossing_s (10 s).
TEST(PlayerController, FlyingFollowsThePitchedViewThroughWallsAtTheScenesSpeed) {
  game_demo::Simulation sim(demo_test::make_room({}), flying());
  const float speed = kRoomDiagonalM / 10.0f;
  EXPECT_NEAR(sim.registry().get<game_demo::PlayerController>(sim.context().camera).fly_speed_m_s, speed, 1e-4f);
  InputFrame look_up;
  look_up.mouse_dy_px = -0.5f / 0.0025f;  // the mouse forward: 0.5 rad up
  sim.step(look_up);
  const glm::vec3 start = eye_of(sim);
  for (int i = 0; i < 60; ++i) sim.step(keys({Key::W}));
  const glm::vec3 moved = eye_of(sim) - start;
  EXPECT_NEAR(glm::length(moved), speed, 1e-3f) << "one second at the fly speed";
  EXPECT_NEAR(moved.y, speed * std::sin(0.5f), 1e-3f);
  EXPECT_NEAR(moved.z, -speed * std::cos(0.5f), 1e-3f);
  for (int i = 0; i < 60; ++i) sim.step(keys({Key::Down}));
  EXPECT_NEAR(eye_of(sim).y, start.y + moved.y - speed, 1e-3f);
  for (int i = 0; i < 60; ++i) sim.step(keys({Key::Up}));
  EXPECT_NEAR(eye_of(sim).y, start.y + moved.y, 1e-3f);
  for (int i = 0; i < 10 * 60; ++i) sim.step(keys({Key::A}));  // 12.7 m to the left: out through the west wall
  EXPECT_LT(eye_of(sim).x, -5.2f);

  // Walking on the same room: no height change, stopped by the wall.
  game_demo::Simulation walk(demo_test::make_room({}));
  walk.step(look_up);
  for (int i = 0; i < 10 * 60; ++i) walk.step(keys({Key::A}));
  EXPECT_GT(eye_of(walk).x, -5.0f);
  EXPECT_FLOAT_EQ(eye_of(walk).y, 1.6f);
}

// A level without a camera (the room's meshes, no camera node) is framed from above a
// diagonal: every corner of its bounds in view, the camera outside them, zfar beyond them.
TEST(PrepareScene, ALevelWithoutACameraIsFramedFromAboveADiagonal) {
  engine::Scene room = demo_test::make_room({});
  engine::SceneAsset a = room.assets;
  a.nodes.erase(std::remove_if(a.nodes.begin(), a.nodes.end(), [](const engine::Node& n) { return n.camera >= 0; }),
                a.nodes.end());
  a.cameras.clear();
  game_demo::Simulation sim(engine::instantiate(std::move(a)), flying());
  const engine::Entity camera = sim.context().camera;
  const engine::Transform& t = sim.registry().get<engine::Transform>(camera);
  const engine::Camera& cam = sim.registry().get<engine::Camera>(camera);
  const glm::vec3 centre(0.0f, 1.5f, 0.0f);
  const glm::vec3 forward = t.rotation * glm::vec3(0.0f, 0.0f, -1.0f);
  EXPECT_GT(glm::dot(glm::normalize(centre - t.position), forward), 0.9999f) << "looking at the centre";
  EXPECT_GT(t.position.y, 3.2f) << "from above";
  EXPECT_GT(t.position.x, 5.2f);
  EXPECT_GT(t.position.z, 3.2f);
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 corner((i & 1) ? 5.2f : -5.2f, (i & 2) ? 3.2f : -0.2f, (i & 4) ? 3.2f : -3.2f);
    const glm::vec3 to = corner - t.position;
    const float angle = std::acos(glm::dot(glm::normalize(to), forward));
    EXPECT_LT(angle, 0.5f * cam.yfov_rad) << "corner " << i << " in the vertical field of view";
    EXPECT_LT(glm::length(to), cam.zfar_m);
    EXPECT_GT(glm::length(to), cam.znear_m);
  }
  EXPECT_NEAR(cam.znear_m, 0.005f * 0.5f * kRoomDiagonalM, 1e-5f);
}

// A camera under a transformed parent starts at its world pose, then moves in world space.
TEST(PrepareScene, ACameraUnderAParentStartsAtItsWorldPose) {
  engine::Scene room = demo_test::make_room({});
  engine::SceneAsset a = room.assets;
  engine::Node rig;
  rig.name = "rig";
  rig.translation = {1.0f, 0.5f, 0.0f};
  rig.rotation = glm::angleAxis(0.5f, glm::vec3(0.0f, 1.0f, 0.0f));
  a.nodes.push_back(rig);
  for (engine::Node& n : a.nodes)
    if (n.camera >= 0) n.parent = static_cast<int>(a.nodes.size() - 1);
  std::rotate(a.nodes.begin(), a.nodes.end() - 1, a.nodes.end());  // parents first
  for (engine::Node& n : a.nodes) n.parent = n.parent >= 0 ? 0 : -1;
  engine::Scene scene = engine::instantiate(std::move(a));
  const engine::Entity cam_entity = engine::find_camera(scene.registry);
  const glm::mat4 world = scene.registry.get<engine::WorldTransform>(cam_entity).matrix;
  game_demo::Simulation sim(std::move(scene), flying());
  const engine::Transform& t = sim.registry().get<engine::Transform>(sim.context().camera);
  EXPECT_FALSE(t.parent);
  EXPECT_NEAR(glm::length(t.position - glm::vec3(world[3])), 0.0f, 1e-5f);
  EXPECT_NEAR(std::abs(glm::dot(t.rotation, glm::quat_cast(glm::mat3(world)))), 1.0f, 1e-5f);
}

// O swings the door of any scene: the demo level's "corridor_door" by name, else the first mesh
// node flagged gi.region "deforming" (corridor.gltf's "door"), between its authored pose and shut.
TEST(Door, OSwingsTheDeformingRegionsMeshWhenTheSceneHasNoCorridorDoor) {
  engine::Scene room = demo_test::make_room({});
  engine::SceneAsset a = room.assets;
  int mesh = -1;
  for (const engine::Node& n : a.nodes) mesh = n.mesh >= 0 && mesh < 0 ? n.mesh : mesh;
  ASSERT_GE(mesh, 0);
  engine::Node door;
  door.name = "vault_door";
  door.mesh = mesh;
  door.translation = {1.0f, 0.0f, 2.0f};
  door.rotation = glm::angleAxis(1.2f, glm::vec3(0.0f, 1.0f, 0.0f));
  door.gi.region = engine::GiRegion::Deforming;
  a.nodes.push_back(door);
  game_demo::Simulation sim(engine::instantiate(std::move(a)), flying());
  const engine::Entity e = sim.context().door;
  ASSERT_FALSE(e.is_null());
  EXPECT_EQ(sim.registry().get<engine::Name>(e).value, "vault_door");
  const glm::quat authored = sim.registry().get<engine::Transform>(e).rotation;
  sim.step(keys({Key::O}));
  EXPECT_NEAR(std::abs(sim.registry().get<engine::Transform>(e).rotation.w), 1.0f, 1e-6f) << "shut";
  sim.step(keys({}));
  sim.step(keys({Key::O}));
  EXPECT_NEAR(std::abs(glm::dot(sim.registry().get<engine::Transform>(e).rotation, authored)), 1.0f, 1e-6f)
      << "open again";
}

}  // namespace
