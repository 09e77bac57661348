#pragma once
// Automatic exposure on the GPU (engine/exposure.h, docs/exposure.md): a compute pass meters
// the HDR frame into a histogram of log2 luminance, a second one-invocation pass adapts the
// EV100 into a one-element state buffer the tonemap reads. Nothing comes back to the CPU
// unless read() is called.
//   auto meter = engine::render::ExposureMeter::create().value();
//   meter.run(hdr_texture, width, height, dt_s, snap, settings.auto_exposure);  // then bind state_buffer()

#include <engine/exposure.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>

#include <engine/result.h>
#include "render/program_uniforms.h"

#include <cstdint>

namespace engine::render {

/// SSBO bindings of exposure_common.glsl (free in every other engine pass).
inline constexpr std::uint32_t kExposureStateBinding = 4;
inline constexpr std::uint32_t kExposureHistogramBinding = 5;

/// Histogram resolution: 256 bins over kMeteredLog2LuminanceMin..Max (32 EV), 1/8 EV each,
/// and where in its bin each pixel falls in 1/16 steps (the sums cannot overflow 32 bits
/// below 2^32 / 15 = 286 M pixels, far beyond the largest target).
inline constexpr int kMeterBins = 256;
inline constexpr int kMeterSubBinSteps = 16;
/// Each invocation of the histogram pass meters PIXELS_PER_SIDE^2 pixels, every
/// kMeteredPixelStride-th of every kMeteredPixelStride-th row, so a work group covers a
/// 128 x 128 tile (8192^2 pixels: 64 x 64 groups, far below the 65535 limit).
inline constexpr int kMeterPixelsPerSide = 4;

/// C++ mirror of exposure_common.glsl's ExposureState (std430).
struct GpuExposureState {
  float exposure = 1.0f;
  float ev100 = 0.0f;
  float target_ev100 = 0.0f;
  float mean_log2_luminance = 0.0f;
  std::uint32_t metered_pixels = 0;
  std::uint32_t pad[3] = {0, 0, 0};
};
static_assert(sizeof(GpuExposureState) == 32, "must match exposure_common.glsl's ExposureState");

/// The #defines the exposure shaders need (exposure_common.glsl), for ShaderProgramBuilder.
ShaderProgramBuilder& define_exposure_constants(ShaderProgramBuilder& builder);

class ExposureMeter {
 public:
  /// Compiles both passes and makes the buffers (histogram zeroed). Needs a current context.
  static Result<ExposureMeter> create();

  /// Meters `hdr` (an RGBA16F texture of width x height), then adapts: `snap` sets the EV100
  /// to this frame's target, otherwise it moves toward it over dt_s seconds.
  void run(std::uint32_t hdr, int width, int height, double dt_s, bool snap, const AutoExposure& settings);

  /// The state buffer (GpuExposureState) the tonemap binds at kExposureStateBinding.
  std::uint32_t state_buffer() const { return state_.id(); }

  /// Reads the state back (synchronous: waits for the passes).
  GpuExposureState read() const;

 private:
  LocatedProgram<ExposureHistogramUniforms> histogram_;
  LocatedProgram<ExposureAdaptUniforms> adapt_;
  GlBuffer histogram_buffer_;
  GlBuffer state_;
};

}  // namespace engine::render
