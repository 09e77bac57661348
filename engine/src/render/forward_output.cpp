// engine::render::ForwardRenderer's output: the tonemap pass (exposure, ACES fitted, sRGB
// into the RGBA8 target), the exposure it was shown with, and the read-back of the LDR and
// HDR targets as top-to-bottom images.
#include "render/forward_renderer.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <GL/glcorearb.h>

#include <engine/exposure.h>

#include "render/exposure_meter.h"

namespace engine::render {

namespace {

// RGBA rows read back from GL (bottom to top) in an image's order (top to bottom).
template <class Channel>
std::vector<Channel> rows_top_down(const std::vector<Channel>& gl_rows, int width, int height) {
  std::vector<Channel> out(gl_rows.size());
  const std::size_t row = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y)
    std::copy_n(gl_rows.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(height - 1 - y)), row,
                out.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y)));
  return out;
}

}  // namespace

void ForwardRenderer::tonemap_pass() {
  glBindFramebuffer(GL_FRAMEBUFFER, ldr_fbo_.id());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  tonemap_.use();
  glUniform1f(tonemap_.uniforms.exposure, exposure_metered_ ? 1.0f : applied_exposure_);
  glUniform1i(tonemap_.uniforms.metered, exposure_metered_ ? 1 : 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kExposureStateBinding, exposure_meter_.state_buffer());
  glBindTextureUnit(0, hdr_.id());
  glBindVertexArray(empty_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

float ForwardRenderer::fixed_exposure() const {
  return settings_.exposure_mode == ExposureMode::FixedEv100 ? exposure_of_ev100(settings_.ev100) : settings_.exposure;
}

ExposureReading ForwardRenderer::read_exposure() const {
  ExposureReading r;
  if (!exposure_metered_) {
    r.exposure = applied_exposure_;
    r.ev100 = r.exposure > 0.0f ? ev100_of_exposure(r.exposure) : 0.0f;
    r.target_ev100 = r.ev100;
    return r;
  }
  const GpuExposureState s = exposure_meter_.read();
  r.exposure = s.exposure;
  r.ev100 = s.ev100;
  r.target_ev100 = s.target_ev100;
  r.mean_log2_luminance = s.mean_log2_luminance;
  r.metered_pixels = s.metered_pixels;
  r.metered = true;
  return r;
}

ImageRgba8 ForwardRenderer::read_ldr() const {
  ImageRgba8 image;
  image.width = width_;
  image.height = height_;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(ldr_.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(raw.size()), raw.data());
  image.pixels = rows_top_down(raw, width_, height_);
  return image;
}

ImageRgbaF ForwardRenderer::read_hdr() const {
  ImageRgbaF image;
  image.width = width_;
  image.height = height_;
  std::vector<float> raw(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(hdr_.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(raw.size() * sizeof(float)), raw.data());
  image.pixels = rows_top_down(raw, width_, height_);
  return image;
}

}  // namespace engine::render
