#include <engine/gpu/gpu_timer.h>

#include <GL/glcorearb.h>

namespace engine {

GpuTimer::GpuTimer() {
  glFinish();
  start_ = std::chrono::steady_clock::now();
}

double GpuTimer::lap_ms() {
  glFinish();
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start_).count();
  start_ = now;
  return ms;
}

}  // namespace engine
