#include <engine/system_schedule.h>

#include <algorithm>

namespace engine {

void SystemSchedule::add(Stage stage, std::string name, SystemFn fn) {
  GI_EXPECTS(fn != nullptr, "a system needs a function");
  for (const Entry& e : systems_) GI_EXPECTS(e.name != name, "system names must be unique");
  systems_.push_back(Entry{stage, std::move(name), std::move(fn), systems_.size()});
  std::stable_sort(systems_.begin(), systems_.end(), [](const Entry& a, const Entry& b) {
    return a.stage != b.stage ? a.stage < b.stage : a.sequence < b.sequence;
  });
}

void SystemSchedule::run(Registry& registry, const FrameTime& time) {
  timings_.clear();
  for (Entry& e : systems_) {
    const auto t0 = std::chrono::steady_clock::now();
    e.fn(registry, time);
    const auto t1 = std::chrono::steady_clock::now();
    timings_.push_back(Timing{e.name, e.stage, std::chrono::duration<double, std::milli>(t1 - t0).count()});
  }
}

std::vector<std::string> SystemSchedule::order() const {
  std::vector<std::string> names;
  for (const Entry& e : systems_) names.push_back(e.name);
  return names;
}

}  // namespace engine
