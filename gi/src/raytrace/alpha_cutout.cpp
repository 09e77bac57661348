#include <algorithm>
#include <cmath>

#include "raytrace/material_textures.h"
#include "raytrace/rt_scene_data.h"

namespace gi {

float RtAlphaCutout::alpha(const std::vector<std::uint32_t>& indices, std::uint32_t triangle, glm::vec2 b) const {
  if (triangle >= triangle_mask.size() || triangle_mask[triangle] < 0) return 1.0f;
  const Mask& m = masks[static_cast<std::size_t>(triangle_mask[triangle])];
  if (m.width <= 0 || m.height <= 0) return m.factor;
  const std::vector<glm::vec2>& uv = m.texcoord == 1 ? uv1 : uv0;
  const std::uint32_t* v = &indices[3u * triangle];
  if (v[0] >= uv.size() || v[1] >= uv.size() || v[2] >= uv.size()) return m.factor;
  const glm::vec2 p =
      engine::transformed_uv(m.transform, (1.0f - b.x - b.y) * uv[v[0]] + b.x * uv[v[1]] + b.y * uv[v[2]]);
  if (!m.sampler.mag_linear) {  // NEAREST: the texel the point lies in
    const float nx = std::floor(p.x * static_cast<float>(m.width)), ny = std::floor(p.y * static_cast<float>(m.height));
    if (!std::isfinite(nx) || !std::isfinite(ny)) return m.factor;
    const int x = wrap_texel(static_cast<int>(std::clamp(nx, -1.0e9f, 1.0e9f)), m.width, m.sampler.wrap_s);
    const int y = wrap_texel(static_cast<int>(std::clamp(ny, -1.0e9f, 1.0e9f)), m.height, m.sampler.wrap_t);
    return m.factor *
           static_cast<float>(
               m.alpha[static_cast<std::size_t>(y) * static_cast<std::size_t>(m.width) + static_cast<std::size_t>(x)]) /
           255.0f;
  }
  const float fx = p.x * static_cast<float>(m.width) - 0.5f;
  const float fy = p.y * static_cast<float>(m.height) - 0.5f;
  if (!std::isfinite(fx) || !std::isfinite(fy)) return m.factor;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  const int x0 = static_cast<int>(std::clamp(x0f, -1.0e9f, 1.0e9f));
  const int y0 = static_cast<int>(std::clamp(y0f, -1.0e9f, 1.0e9f));
  const auto at = [&](int x, int y) {
    x = wrap_texel(x, m.width, m.sampler.wrap_s);
    y = wrap_texel(y, m.height, m.sampler.wrap_t);
    return static_cast<float>(
               m.alpha[static_cast<std::size_t>(y) * static_cast<std::size_t>(m.width) + static_cast<std::size_t>(x)]) /
           255.0f;
  };
  const float a = (1.0f - ay) * ((1.0f - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
                  ay * ((1.0f - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
  return m.factor * a;
}

bool RtAlphaCutout::cut(const std::vector<std::uint32_t>& indices, std::uint32_t triangle, glm::vec2 bary) const {
  if (triangle >= triangle_mask.size() || triangle_mask[triangle] < 0) return false;
  return alpha(indices, triangle, bary) < masks[static_cast<std::size_t>(triangle_mask[triangle])].cutoff;
}

}  // namespace gi
