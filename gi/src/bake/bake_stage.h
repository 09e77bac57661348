#pragma once
// One stage of gi::bake_bundle (a method, a mesh, a shard): its log lines and its progress,
// reported to the host under the stage's name.
//   const gi::BakeStage stage{host, "PRM"};
//   stage.log(gi::format_line("PRM of %s: %d clusters", name.c_str(), clusters));

#include <gi/bake.h>
#include <gi/progress.h>

#include <string>

namespace gi {

struct BakeStage {
  const BakeHost& host;
  std::string name;

  /// Sends `line` to the host's log at Info level (nothing when the host has no log).
  void log(const std::string& line) const {
    if (host.log) host.log(LogLevel::Info, line);
  }
  /// The host's progress under this stage's name (empty when the host has none).
  ProgressCallback progress() const {
    if (!host.progress) return {};
    return [this](double f) { return host.progress(name, f); };
  }
};

/// printf-style formatting of one log line (truncated at 511 characters).
__attribute__((format(printf, 1, 2))) std::string format_line(const char* fmt, ...);

/// The scene's file name for log lines ("the scene" when it has none).
std::string scene_file_name(const BakeInput& input);

}  // namespace gi
