#pragma once
// A one-line progress bar with an ETA for a whole sweep, redrawn on a terminal stream
// (stderr) at most every `min_interval_s`; plain lines when the stream is not a terminal.
//   gi::SweepProgressBar bar(std::cerr, isatty(2));
//   auto result = gi::run_sweep(registry, method, scene, settings, options, [&](auto& p) { return bar.update(p); });

#include <chrono>
#include <ostream>
#include <string>

#include "sweep/sweep_runner.h"

namespace gi {

/// "[#########.........] 3/8  37%  run spp=16 (42%)  elapsed 0:12  ETA 0:20".
/// ETA = elapsed * (1 - f) / f with f = (units done + current fraction) / units total.
std::string format_sweep_progress(const SweepProgress& p, double elapsed_s, int bar_width = 24);

/// "1:05", "1:02:03", or "--:--" for a negative/unknown time.
std::string format_duration(double seconds);

class SweepProgressBar {
 public:
  SweepProgressBar(std::ostream& out, bool terminal, double min_interval_s = 0.1);
  /// Draws (throttled; always draws when a unit completes). Returns `!cancel_requested()`.
  bool update(const SweepProgress& p);
  /// Ends the line.
  void finish();
  /// Makes update() return false from now on (a signal handler's flag is checked by the caller).
  void request_cancel() { cancel_ = true; }

 private:
  std::ostream& out_;
  bool terminal_;
  double min_interval_s_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_draw_{};
  std::size_t last_units_done_ = static_cast<std::size_t>(-1);
  std::size_t last_width_ = 0;
  bool cancel_ = false;
};

}  // namespace gi
