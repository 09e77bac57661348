// gi_demo's scripts: --script none (a still camera, the default for any scene but the demo level).
#include <gtest/gtest.h>

#include <engine/components.h>
#include <game_demo/scripted_pilot.h>
#include <game_demo/simulation.h>

#include "demo/test_room.h"

using game_demo::Script;

TEST(ScriptedPilot, DefaultIsTheTourOnTheDemoLevelAndAStillCameraElsewhere) {
  EXPECT_EQ(game_demo::default_script(""), Script::Tour);
  EXPECT_EQ(game_demo::default_script("assets/demo_level.gltf"), Script::Tour);
  EXPECT_EQ(game_demo::default_script("/elsewhere/demo_level.draco.glb"), Script::Tour);
  EXPECT_EQ(game_demo::default_script("assets/cornell_box.gltf"), Script::None);
  EXPECT_EQ(game_demo::default_script("../shared/external-assets/Avocado.glb"), Script::None);
  EXPECT_EQ(game_demo::script_from_name("none"), Script::None);
  EXPECT_EQ(game_demo::script_name(Script::None), "none");
}

TEST(ScriptedPilot, NoneLeavesTheCameraStillTheFlashlightOffAndOneView) {
  for (Script script : {Script::None, Script::Tour}) {
    game_demo::Simulation sim(demo_test::make_room({}, {1.0f, 1.6f, 2.0f}));
    const engine::Registry& reg = sim.registry();
    const engine::Entity camera = sim.context().camera;
    const engine::Transform start = reg.get<engine::Transform>(camera);
    game_demo::ScriptedPilot pilot(sim, script, 120);
    for (int i = 0; i < 120; ++i) sim.step(pilot.next(sim));
    const engine::Transform& end = reg.get<engine::Transform>(camera);
    const bool still = end.position == start.position && end.rotation == start.rotation;
    // The tour (the contrast that makes this test able to fail) walks, turns the flashlight
    // on at frame 10 and splits the screen at frame 60.
    EXPECT_EQ(still, script == Script::None) << game_demo::script_name(script);
    EXPECT_EQ(reg.get<engine::Light>(sim.context().flashlight).enabled, script == Script::Tour);
    EXPECT_EQ(sim.context().split_view, script == Script::Tour);
  }
}

// A model without a camera (the Avocado): the camera frames the object instead of standing
// 1.6 m above its floor, so --script none shows it.
TEST(ScriptedPilot, ASmallObjectWithoutACameraIsFramed) {
  engine::SceneAsset a;
  a.meshes.push_back(demo_test::box_mesh(glm::vec3(0.05f)));
  engine::Node n;
  n.name = "model";
  n.mesh = 0;
  n.translation = {0.2f, 0.05f, -0.1f};
  a.nodes.push_back(n);
  game_demo::Simulation sim(engine::instantiate(std::move(a)));
  const engine::Entity camera = sim.context().camera;
  const engine::Transform& t = sim.registry().get<engine::Transform>(camera);
  const glm::vec3 to_model = glm::vec3(0.2f, 0.05f, -0.1f) - t.position;
  const glm::vec3 forward = t.rotation * glm::vec3(0.0f, 0.0f, -1.0f);
  EXPECT_GT(glm::dot(glm::normalize(to_model), forward), 0.999f) << "looking at it";
  EXPECT_LT(glm::length(to_model), 1.0f) << "close to it";
  EXPECT_LT(sim.registry().get<engine::Camera>(camera).znear_m, 0.01f);
}
