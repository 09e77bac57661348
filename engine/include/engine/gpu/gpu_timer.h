#pragma once
// Wall-clock timing of GPU passes: glFinish before and after, steady clock in between.
// Timer queries (GL_TIME_ELAPSED) are meaningless on llvmpipe (DESIGN.md section 4), so this
// is what timings on the test machines mean: CPU-side time of the whole pass.
//   engine::GpuTimer t;  draw_shadows();  double ms = t.lap_ms();

#include <chrono>

namespace engine {

class GpuTimer {
 public:
  /// Calls glFinish() so earlier work is not billed to the pass, then starts the clock.
  GpuTimer();
  /// glFinish(), then the milliseconds since construction or the previous lap; restarts.
  double lap_ms();

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace engine
