#pragma once
// Systems run in a fixed order: by stage, then by the order they were added.
//   engine::SystemSchedule schedule;
//   schedule.add(engine::Stage::Gameplay, "move_crates", [](engine::Registry& r, const engine::FrameTime& t) {...});
//   schedule.run(registry, {.dt_s = 1.0 / 60.0, .frame = n});

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <engine/registry.h>

namespace engine {

/// The stages of a frame, in execution order.
enum class Stage : std::uint8_t { Input, Gameplay, Physics, Transform, Lighting, PreRender };

/// The fixed simulation step.
struct FrameTime {
  double dt_s = 1.0 / 60.0;
  std::uint64_t frame = 0;
  double time_s = 0.0;
};

using SystemFn = std::function<void(Registry&, const FrameTime&)>;

class SystemSchedule {
 public:
  /// Adds a system; names must be unique (they label timings in the overlay).
  void add(Stage stage, std::string name, SystemFn fn);

  /// Runs every system once, in order, and records each one's CPU time.
  void run(Registry& registry, const FrameTime& time);

  struct Timing {
    std::string name;
    Stage stage;
    double cpu_ms;
  };
  /// CPU time of each system in the last run(), in execution order.
  const std::vector<Timing>& last_timings() const { return timings_; }

  /// The system names in execution order.
  std::vector<std::string> order() const;

 private:
  struct Entry {
    Stage stage;
    std::string name;
    SystemFn fn;
    std::size_t sequence;
  };
  std::vector<Entry> systems_;
  std::vector<Timing> timings_;
};

}  // namespace engine
