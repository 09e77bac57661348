#pragma once
// Elapsed wall-clock time for bake statistics and progress reports, on the steady clock.
//   const auto start = std::chrono::steady_clock::now();
//   stats.seconds = gi::seconds_since(start);

#include <chrono>

namespace gi {

/// Seconds (double) elapsed on std::chrono::steady_clock since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace gi
