#pragma once
// A progress bar for the command-line tools: "[#######.....]  42%  elapsed 0:12  ETA 0:16"
// on stderr, redrawn in place on a terminal, one line every 2 s otherwise (CI logs).
//   settings.progress = tools::console_progress("bake");

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include <gi/progress.h>

#include "sweep/sweep_progress_bar.h"

namespace tools {

inline gi::ProgressCallback console_progress(const std::string& label) {
  using Clock = std::chrono::steady_clock;
  const bool terminal = isatty(2) != 0;
  const auto start = Clock::now();
  auto last = start - std::chrono::seconds(1);
  return [=](double f) mutable {
    const auto now = Clock::now();
    if (f < 1.0 && now - last < std::chrono::milliseconds(terminal ? 100 : 2000)) return true;
    last = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    const int filled = static_cast<int>(f * 30.0);
    std::fprintf(stderr, "%s%s [%s%s] %3d%%  elapsed %s  ETA %s%s", terminal ? "\r" : "", label.c_str(),
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(30 - filled), '.').c_str(), static_cast<int>(f * 100.0),
                 gi::format_duration(elapsed).c_str(), gi::format_duration(f > 0.0 ? elapsed * (1.0 - f) / f : -1.0).c_str(),
                 terminal && f < 1.0 ? "" : "\n");
    return true;
  };
}

}  // namespace tools
