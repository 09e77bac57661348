#include <engine/system_schedule.h>

#include <gtest/gtest.h>

namespace {

TEST(SystemSchedule, RunsByStageThenInsertionOrder) {
  engine::SystemSchedule schedule;
  std::vector<std::string> ran;
  auto record = [&ran](std::string name) {
    return [&ran, name](engine::Registry&, const engine::FrameTime&) { ran.push_back(name); };
  };
  schedule.add(engine::Stage::Transform, "transforms", record("transforms"));
  schedule.add(engine::Stage::Gameplay, "player", record("player"));
  schedule.add(engine::Stage::Input, "input", record("input"));
  schedule.add(engine::Stage::Gameplay, "push", record("push"));
  engine::Registry reg;
  schedule.run(reg, {});
  const std::vector<std::string> expected{"input", "player", "push", "transforms"};
  EXPECT_EQ(ran, expected);
  EXPECT_EQ(schedule.order(), expected);
  ASSERT_EQ(schedule.last_timings().size(), 4u);
  EXPECT_EQ(schedule.last_timings()[1].name, "player");
  EXPECT_GE(schedule.last_timings()[1].cpu_ms, 0.0);
}

TEST(SystemScheduleDeathTest, DuplicateNamesAreRejected) {
  engine::SystemSchedule schedule;
  schedule.add(engine::Stage::Input, "a", [](engine::Registry&, const engine::FrameTime&) {});
  EXPECT_DEATH(schedule.add(engine::Stage::Gameplay, "a", [](engine::Registry&, const engine::FrameTime&) {}),
               "system names must be unique");
}

}  // namespace
