#include <engine/directional_radiance.h>

#include <algorithm>
#include <cmath>

namespace engine {

float directional_bin_alpha(int bin_count) {
  const float n = static_cast<float>(std::max(bin_count, 2));
  const float theta = std::acos(std::clamp(1.0f - 2.0f / n, -1.0f, 1.0f));
  return std::tan(0.5f * theta);
}

glm::vec3 directional_specular(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                               std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance) {
  const float a_bin = directional_bin_alpha(static_cast<int>(directions.size()));
  const float a = std::sqrt(m.alpha * m.alpha + a_bin * a_bin);
  const float n_dot_v = std::max(glm::dot(n, v), 1e-4f);
  float sum_w = 0.0f;
  glm::vec3 sum(0.0f);
  const std::size_t count = std::min(directions.size(), radiance.size());
  for (std::size_t k = 0; k < count; ++k) {
    const glm::vec3 l = directions[k];
    const float n_dot_l = glm::dot(n, l);
    if (!(n_dot_l > kDirectionalMinCos)) continue;
    const glm::vec3 s = l + v;
    const float len2 = glm::dot(s, s);
    const glm::vec3 h = len2 > 1e-12f ? s / std::sqrt(len2) : n;
    const float n_dot_h = std::clamp(glm::dot(n, h), 0.0f, 1.0f);
    const float w = gltf_ggx_distribution(n_dot_h, a) * gltf_smith_visibility(n_dot_v, n_dot_l, a) * n_dot_l;
    sum_w += w;
    sum += w * radiance[k];
  }
  if (!(sum_w > 0.0f)) return glm::vec3(0.0f);
  return gltf_directional_albedo(m, glm::dot(n, v)).specular * (sum / sum_w);
}

}  // namespace engine
