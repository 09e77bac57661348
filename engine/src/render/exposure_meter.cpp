// Automatic exposure's two GPU passes (render/exposure_meter.h) and the camera model's CPU
// functions (engine/exposure.h).
#include "render/exposure_meter.h"

#include <GL/glcorearb.h>
#include <engine/check.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace engine {

float exposure_of_ev100(float ev100) { return units::kLumensPerWatt / (kSaturationScale * std::exp2(ev100)); }

float ev100_of_exposure(float exposure) {
  GI_EXPECTS(exposure > 0.0f, "ev100_of_exposure needs a positive exposure");
  return std::log2(units::kLumensPerWatt / (kSaturationScale * exposure));
}

float ev100_of_luminance(float average_luminance_cd_m2) {
  GI_EXPECTS(average_luminance_cd_m2 > 0.0f, "ev100_of_luminance needs a positive luminance");
  return std::log2(average_luminance_cd_m2) + kMeterEvOffset;
}

float adapt_ev100(float current, float target, double dt_s, const AutoExposure& s) {
  const float rate = target > current ? s.brighter_rate_per_s : s.darker_rate_per_s;
  return target + (current - target) * std::exp(-rate * static_cast<float>(dt_s));
}

}  // namespace engine

namespace engine::render {

namespace {

template <class Uniforms>
Result<LocatedProgram<Uniforms>> build_pass(const char* file) {
  ShaderProgramBuilder b(engine_shader_files());
  return link_program<Uniforms>(define_exposure_constants(b), {{ShaderStage::Compute, file}});
}

}  // namespace

ShaderProgramBuilder& define_exposure_constants(ShaderProgramBuilder& b) {
  static_assert(kMeterBins == 16 * 16, "the histogram pass merges one bin per invocation of its 16 x 16 group");
  constexpr float kBinsPerEv = kMeterBins / (kMeteredLog2LuminanceMax - kMeteredLog2LuminanceMin);
  static_assert(kBinsPerEv == 8.0f, "256 bins over 32 EV");
  return b.define("EXPOSURE_STATE_BINDING " + std::to_string(kExposureStateBinding))
      .define("EXPOSURE_HISTOGRAM_BINDING " + std::to_string(kExposureHistogramBinding))
      .define("METER_BINS " + std::to_string(kMeterBins))
      .define("BINS_PER_EV " + std::to_string(static_cast<int>(kBinsPerEv)))
      .define("SUB_BIN_STEPS " + std::to_string(kMeterSubBinSteps))
      // std::to_string(float) writes fixed notation, always with a '.': GLSL float literals.
      .define("METER_MIN_LOG2 " + std::to_string(kMeteredLog2LuminanceMin))
      .define("METER_EV_OFFSET " + std::to_string(kMeterEvOffset))
      .define("LUMENS_PER_WATT " + std::to_string(units::kLumensPerWatt))
      .define("SATURATION_SCALE " + std::to_string(kSaturationScale))
      .define("PIXELS_PER_SIDE " + std::to_string(kMeterPixelsPerSide))
      .define("METER_STRIDE " + std::to_string(kMeteredPixelStride));
}

Result<ExposureMeter> ExposureMeter::create() {
  auto histogram = build_pass<ExposureHistogramUniforms>("exposure_histogram.comp.glsl");
  if (!histogram) return histogram.error();
  auto adapt = build_pass<ExposureAdaptUniforms>("exposure_adapt.comp.glsl");
  if (!adapt) return adapt.error();
  ExposureMeter m;
  m.histogram_ = std::move(histogram.value());
  m.adapt_ = std::move(adapt.value());
  const std::vector<std::uint32_t> zeros(2 * kMeterBins, 0u);
  m.histogram_buffer_ = GlBuffer::create(zeros.size() * sizeof(std::uint32_t), zeros.data());
  const GpuExposureState initial{};
  m.state_ = GlBuffer::create(sizeof(GpuExposureState), &initial);
  return m;
}

void ExposureMeter::run(std::uint32_t hdr, int width, int height, double dt_s, bool snap, const AutoExposure& s) {
  GI_EXPECTS(width > 0 && height > 0, "the metered frame must not be empty");
  GI_EXPECTS(std::isfinite(dt_s) && dt_s >= 0.0, "the frame's time step must be finite and not negative");
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kExposureHistogramBinding, histogram_buffer_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kExposureStateBinding, state_.id());
  // The previous frame's adapt pass cleared the histogram and wrote the state.
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  histogram_.use();
  glBindTextureUnit(0, hdr);
  glUniform2i(histogram_.uniforms.size, width, height);
  constexpr int tile = 16 * kMeterPixelsPerSide * kMeteredPixelStride;
  glDispatchCompute(static_cast<GLuint>((width + tile - 1) / tile), static_cast<GLuint>((height + tile - 1) / tile), 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

  adapt_.use();
  const ExposureAdaptUniforms& u = adapt_.uniforms;
  glUniform1f(u.dt_s, static_cast<float>(dt_s));
  glUniform1i(u.snap, snap ? 1 : 0);
  const float low = std::clamp(s.low_percentile, 0.0f, 1.0f);
  glUniform2f(u.percentiles, low, std::clamp(s.high_percentile, low, 1.0f));
  glUniform2f(u.ev100_range, s.min_ev100, std::max(s.min_ev100, s.max_ev100));
  glUniform1f(u.compensation_ev, s.compensation_ev);
  glUniform2f(u.rates_per_s, std::max(0.0f, s.brighter_rate_per_s), std::max(0.0f, s.darker_rate_per_s));
  glDispatchCompute(1, 1, 1);
  // The tonemap's fragment shader reads the state; the next frame's passes read both buffers.
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

GpuExposureState ExposureMeter::read() const {
  GpuExposureState s;
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(state_.id(), 0, sizeof s, &s);
  return s;
}

}  // namespace engine::render
