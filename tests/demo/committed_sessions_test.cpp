// The committed sessions (tests/sessions/*.girec, recorded on assets/demo_level.gltf by
// tools/record-sessions.sh) replay headlessly to the very checksums they were recorded with.
#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include <game_demo/replay.h>

namespace {

std::filesystem::path sessions_dir() { return std::filesystem::path(GI_SOURCE_DIR) / "tests" / "sessions"; }

void expect_replays(const std::string& name, std::size_t min_frames) {
  const std::filesystem::path file = sessions_dir() / (name + ".girec");
  auto session = game_demo::load_session(file);
  ASSERT_TRUE(session) << session.error().to_string();
  EXPECT_EQ(session->header.scene_path, "assets/demo_level.gltf");
  EXPECT_GE(session->frames.size(), min_frames);
  auto sim = game_demo::simulation_for_session(*session, file.string());
  ASSERT_TRUE(sim) << sim.error().to_string();
  const game_demo::ReplayOutcome out = game_demo::replay_inputs(*sim, *session);
  ASSERT_FALSE(out.mismatch.has_value()) << file << ": " << game_demo::describe(*out.mismatch);
  EXPECT_EQ(out.frames_replayed, session->frames.size());
}

TEST(CommittedSessions, WalkFlashlightReplaysToIdenticalChecksums) { expect_replays("walk_flashlight", 600); }
TEST(CommittedSessions, PushCratesReplaysToIdenticalChecksums) { expect_replays("push_crates", 600); }
TEST(CommittedSessions, SplitScreenReplaysToIdenticalChecksums) { expect_replays("split_screen", 300); }
TEST(CommittedSessions, OpenDoorReplaysToIdenticalChecksums) { expect_replays("open_door", 160); }
TEST(CommittedSessions, PushCratesWallReplaysToIdenticalChecksums) { expect_replays("push_crates_wall", 300); }

TEST(CommittedSessions, SessionsExerciseTheirFeatures) {
  // The scripted streams really contain what their names promise.
  auto count_presses = [](const std::string& name, game_demo::Key k) {
    auto s = game_demo::load_session(sessions_dir() / (name + ".girec"));
    EXPECT_TRUE(s) << s.error().to_string();
    if (!s) return 0;
    int n = 0;
    std::uint32_t prev = 0;
    for (const auto& f : s->frames) {
      if (f.input.held(k) && !(prev & game_demo::key_bit(k))) ++n;
      prev = f.input.keys;
    }
    return n;
  };
  EXPECT_EQ(count_presses("walk_flashlight", game_demo::Key::F), 2);
  EXPECT_GE(count_presses("push_crates", game_demo::Key::E), 2);
  EXPECT_EQ(count_presses("split_screen", game_demo::Key::G), 3);
  EXPECT_EQ(count_presses("open_door", game_demo::Key::O), 2);
}

// open_door closes the corridor door (rotation about its hinge to identity), then opens it
// again to its authored rotation.
TEST(CommittedSessions, OpenDoorClosesAndReopensTheDoor) {
  const std::filesystem::path file = sessions_dir() / "open_door.girec";
  auto session = game_demo::load_session(file);
  ASSERT_TRUE(session) << session.error().to_string();
  auto sim = game_demo::simulation_for_session(*session, file.string());
  ASSERT_TRUE(sim) << sim.error().to_string();
  const engine::Entity door = engine::find_by_name(sim->registry(), "corridor_door");
  ASSERT_FALSE(door.is_null());
  const glm::quat open = sim->registry().get<engine::Transform>(door).rotation;
  bool was_closed = false;
  for (const auto& f : session->frames) {
    sim->step(f.input);
    was_closed = was_closed || sim->registry().get<engine::Transform>(door).rotation == glm::quat(1, 0, 0, 0);
  }
  EXPECT_TRUE(was_closed);
  EXPECT_EQ(sim->registry().get<engine::Transform>(door).rotation, open);
}

TEST(CommittedSessions, PushCratesMovesCrates) {
  const std::filesystem::path file = sessions_dir() / "push_crates.girec";
  auto session = game_demo::load_session(file);
  ASSERT_TRUE(session) << session.error().to_string();
  auto sim = game_demo::simulation_for_session(*session, file.string());
  ASSERT_TRUE(sim) << sim.error().to_string();
  std::vector<glm::vec3> before;
  for (engine::Entity c : game_demo::crates_of(sim->registry()))
    before.push_back(sim->registry().get<engine::Transform>(c).position);
  (void)game_demo::replay_inputs(*sim, *session);
  int moved = 0;
  const auto crates = game_demo::crates_of(sim->registry());
  for (std::size_t i = 0; i < crates.size(); ++i)
    if (glm::length(sim->registry().get<engine::Transform>(crates[i]).position - before[i]) > 0.3f) ++moved;
  EXPECT_GE(moved, 2);
}

// push_crates_wall (script crate_to_wall) leaves the red crate against the crate room's wall
// x = 8.2 and the camera on the hub's side of that wall (x < 8), facing it: its golden frame
// (tests/golden/goldens.txt) is the wall seen from outside with the crate right behind it.
TEST(CommittedSessions, PushCratesWallPutsTheRedCrateAgainstTheWallAndTheCameraBehindIt) {
  const std::filesystem::path file = sessions_dir() / "push_crates_wall.girec";
  auto session = game_demo::load_session(file);
  ASSERT_TRUE(session) << session.error().to_string();
  auto sim = game_demo::simulation_for_session(*session, file.string());
  ASSERT_TRUE(sim) << sim.error().to_string();
  const engine::Entity red = engine::find_by_name(sim->registry(), "crate_red");
  ASSERT_FALSE(red.is_null());
  (void)game_demo::replay_inputs(*sim, *session);
  const game_demo::Aabb box = game_demo::crate_box(sim->registry(), red, 0.0f);
  EXPECT_NEAR(box.min.x, 8.2f, 0.05f);                // against the wall
  EXPECT_TRUE(box.max.z < 3.4f || box.min.z > 4.6f);  // beside the doorway (z 3.4..4.6), not in it
  const glm::vec3 eye = sim->registry().get<engine::Transform>(sim->context().camera).position;
  EXPECT_LT(eye.x, 7.9f);
  const glm::vec3 view =
      game_demo::forward_of_yaw(sim->registry().get<game_demo::PlayerController>(sim->context().camera).yaw_rad);
  glm::vec3 to_crate = box.center() - eye;
  to_crate.y = 0.0f;
  EXPECT_GT(glm::dot(glm::normalize(to_crate), view), 0.98f);
}

}  // namespace
