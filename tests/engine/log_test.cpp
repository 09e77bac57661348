// engine/log.h: one callback receives every engine message (here the glTF loader's warning
// about a camera it skips); without one, messages go to stderr with their level.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <engine/gltf.h>
#include <engine/log.h>

namespace {

namespace fs = std::filesystem;

struct Captured {
  engine::LogLevel level;
  std::string message;
};

// Installs a recording callback for the test's lifetime and restores the previous one.
class RecordingLog {
 public:
  RecordingLog() {
    previous_ = engine::set_log_callback([this](engine::LogLevel level, std::string_view message) {
      lines.push_back({level, std::string(message)});
    });
  }
  ~RecordingLog() { engine::set_log_callback(std::move(previous_)); }
  RecordingLog(const RecordingLog&) = delete;
  RecordingLog& operator=(const RecordingLog&) = delete;
  std::vector<Captured> lines;

 private:
  engine::LogCallback previous_;
};

TEST(EngineLog, CallbackReceivesTheGltfLoadersWarning) {
  const fs::path path = fs::temp_directory_path() / "engine_log_test_orthographic.gltf";
  {
    std::ofstream out(path);
    out << R"({"asset": {"version": "2.0"},
      "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0, "zfar": 10}}],
      "nodes": [{"camera": 0}], "scenes": [{"nodes": [0]}], "scene": 0})";
  }
  RecordingLog log;
  const auto scene = engine::load_gltf(path);
  ASSERT_TRUE(scene.ok()) << scene.error().to_string();
  EXPECT_TRUE(scene->cameras.empty());
  ASSERT_EQ(log.lines.size(), 1u);
  EXPECT_EQ(log.lines[0].level, engine::LogLevel::Warning);
  EXPECT_NE(log.lines[0].message.find("orthographic camera skipped"), std::string::npos) << log.lines[0].message;
  EXPECT_NE(log.lines[0].message.find(path.filename().string()), std::string::npos) << log.lines[0].message;
  fs::remove(path);
}

TEST(EngineLog, WithoutACallbackMessagesGoToStderrWithTheirLevel) {
  const engine::LogCallback previous = engine::set_log_callback(nullptr);
  testing::internal::CaptureStderr();
  engine::log_message(engine::LogLevel::Warning, "a test message");
  const std::string printed = testing::internal::GetCapturedStderr();
  engine::set_log_callback(previous);
  EXPECT_EQ(printed, "engine warning: a test message\n");
}

TEST(EngineLog, SetLogCallbackReturnsThePreviousOne) {
  int calls = 0;
  const engine::LogCallback before = engine::set_log_callback([&](engine::LogLevel, std::string_view) { ++calls; });
  engine::log_message(engine::LogLevel::Info, "one");
  const engine::LogCallback mine = engine::set_log_callback(before);
  ASSERT_TRUE(mine);
  mine(engine::LogLevel::Info, "two");
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(engine::log_level_name(engine::LogLevel::Error), "error");
}

}  // namespace
