#include "system/dlm_lighting.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/packing.hpp>

#include "core/half_scale.h"

namespace gi {

engine::Result<std::unique_ptr<DlmLighting>> DlmLighting::from_bake(Dlm dlm, int width, int height) {
  if (dlm.width != width || dlm.height != height)
    return engine::Error{"", "dlm",
                         "the directional light maps are " + std::to_string(dlm.width) + "x" +
                             std::to_string(dlm.height) + " texels, the static meshes' uv1 layout " +
                             std::to_string(width) + "x" + std::to_string(height) + " (re-bake)"};
  const std::size_t elements = dlm.texels.size(), bins = dlm.directions.size();
  if (dlm.radiance.size() != bins * elements * 3)
    return engine::Error{"", "dlm", "the maps' radiance array does not match their texels and directions"};
  // The renderer's nearest-bin search walks the directions by z (engine::directional_bin_of).
  if (!std::is_sorted(dlm.directions.begin(), dlm.directions.end(),
                      [](const glm::vec3& p, const glm::vec3& q) { return p.z > q.z; }))
    return engine::Error{"", "dlm", "the maps' directions are not sorted by decreasing z (re-bake)"};
  std::unique_ptr<DlmLighting> l(new DlmLighting());
  l->width_ = width;
  l->height_ = height;
  l->bins_ = static_cast<int>(bins);
  l->elements_ = elements;
  l->tangent_frame_ = dlm.settings.tangent_frame_bins;
  l->index_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), -1);
  for (std::size_t i = 0; i < elements; ++i) l->index_[dlm.texels[i]] = static_cast<std::int32_t>(i);
  l->packed_.resize(bins * elements);
  for (std::size_t k = 0; k < bins; ++k) {
    const float* first = dlm.radiance.data() + k * elements * 3;
    const float max_value = elements == 0 ? 0.0f : *std::max_element(first, first + elements * 3);
    const float scale = half_layer_scale(max_value);  // as dlm.bin stores it
    l->directions_.emplace_back(dlm.directions[k], scale);
    for (std::size_t i = 0; i < elements; ++i) {
      const float* v = first + i * 3;
      l->packed_[k * elements + i] = glm::uvec2(glm::packHalf2x16(glm::vec2(v[0], v[1]) / scale),
                                                glm::packHalf2x16(glm::vec2(v[2] / scale, 0.0f)));
    }
  }
  return l;
}

std::size_t DlmLighting::gpu_bytes() const {
  return elements_ * static_cast<std::size_t>(bins_) * sizeof(glm::uvec2) +
         static_cast<std::size_t>(bins_) * sizeof(glm::vec4) +
         static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4;
}

void DlmLighting::fill(engine::IndirectLightFrame& frame) {
  if (elements_ == 0 || bins_ == 0) return;
  if (index_texture_.empty()) {
    engine::GlTexture t = engine::GlTexture::create_2d(GL_R32I, width_, height_);
    glTextureSubImage2D(t.id(), 0, 0, 0, width_, height_, GL_RED_INTEGER, GL_INT, index_.data());
    glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    index_texture_ = std::move(t);
    radiance_buffer_ = engine::GlBuffer::create(packed_.size() * sizeof(glm::uvec2), packed_.data());
    direction_buffer_ = engine::GlBuffer::create(directions_.size() * sizeof(glm::vec4), directions_.data());
    index_ = {};
    packed_ = {};
  }
  // packed_ and directions_ were uploaded as the elements the renderer reads.
  static_assert(sizeof(glm::uvec2) == sizeof(engine::DirectionalRadiance), "one DirectionalRadiance per uvec2");
  static_assert(sizeof(glm::vec4) == sizeof(engine::DirectionalBin), "one DirectionalBin per vec4");
  frame.directional_index_texture = {index_texture_.id()};
  frame.directional_radiance_buffer = {radiance_buffer_.id()};
  frame.directional_direction_buffer = {direction_buffer_.id()};
  frame.directional_bin_count = bins_;
  frame.directional_element_count = static_cast<int>(elements_);
  frame.directional_tangent_frame = tangent_frame_;
}

}  // namespace gi
