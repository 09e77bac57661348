#include "antiradiance/directional_bins.h"

#include <engine/check.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace gi {

glm::vec2 DirectionalBins::octahedral_uv(const glm::vec3& d) {
  const float s = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
  glm::vec3 p = s > 0.0f ? d / s : glm::vec3(0.0f, 0.0f, 1.0f);
  glm::vec2 e(p.x, p.y);
  if (p.z < 0.0f) {
    e = glm::vec2((1.0f - std::abs(p.y)) * (p.x >= 0.0f ? 1.0f : -1.0f),
                  (1.0f - std::abs(p.x)) * (p.y >= 0.0f ? 1.0f : -1.0f));
  }
  return e * 0.5f + 0.5f;
}

glm::vec3 DirectionalBins::octahedral_direction(glm::vec2 uv) {
  const glm::vec2 e = uv * 2.0f - 1.0f;
  glm::vec3 p(e.x, e.y, 1.0f - std::abs(e.x) - std::abs(e.y));
  if (p.z < 0.0f) {
    const float x = (1.0f - std::abs(e.y)) * (e.x >= 0.0f ? 1.0f : -1.0f);
    const float y = (1.0f - std::abs(e.x)) * (e.y >= 0.0f ? 1.0f : -1.0f);
    p.x = x;
    p.y = y;
  }
  return glm::normalize(p);
}

DirectionalBins::DirectionalBins(int cells_per_side) : n_(cells_per_side) {
  GI_EXPECTS(cells_per_side >= 1 && cells_per_side <= 64, "DirectionalBins: cells per side must lie in [1, 64]");
  const int m = n_ * n_;
  directions_.assign(static_cast<std::size_t>(m), glm::vec3(0.0f));
  solid_angles_.assign(static_cast<std::size_t>(m), 0.0f);
  // Solid angle and mean direction per cell from a fine sub-grid of the octahedral square:
  // the square's area element maps to the sphere with Jacobian measured by the cross product
  // of the mapped sub-cell edges (exact in the limit; 32 x 32 sub-cells per cell).
  constexpr int kSub = 32;
  const float h = 1.0f / static_cast<float>(n_ * kSub);
  std::vector<double> omega(static_cast<std::size_t>(m), 0.0);
  std::vector<glm::dvec3> mean(static_cast<std::size_t>(m), glm::dvec3(0.0));
  for (int y = 0; y < n_ * kSub; ++y)
    for (int x = 0; x < n_ * kSub; ++x) {
      const glm::vec2 uv0(static_cast<float>(x) * h, static_cast<float>(y) * h);
      const glm::vec3 a = octahedral_direction(uv0 + glm::vec2(0.5f * h, 0.5f * h));
      // Spherical quad area by two triangles of the mapped corners (small cells: flat is fine).
      const glm::dvec3 p00(octahedral_direction(uv0)), p10(octahedral_direction(uv0 + glm::vec2(h, 0.0f)));
      const glm::dvec3 p01(octahedral_direction(uv0 + glm::vec2(0.0f, h))),
          p11(octahedral_direction(uv0 + glm::vec2(h, h)));
      const double area =
          0.5 * glm::length(glm::cross(p10 - p00, p11 - p00)) + 0.5 * glm::length(glm::cross(p11 - p00, p01 - p00));
      const std::size_t j = static_cast<std::size_t>((y / kSub) * n_ + x / kSub);
      omega[j] += area;
      mean[j] += area * glm::dvec3(a);
    }
  double total = 0.0;
  for (double w : omega) total += w;
  min_solid_angle_ = 4.0f * glm::pi<float>();
  for (std::size_t j = 0; j < omega.size(); ++j) {
    // Normalize so the bins sum to exactly 4 pi (the flat sub-triangles lose ~1e-4).
    solid_angles_[j] = static_cast<float>(omega[j] * 4.0 * glm::pi<double>() / total);
    directions_[j] = glm::vec3(glm::normalize(mean[j]));
    min_solid_angle_ = std::min(min_solid_angle_, solid_angles_[j]);
  }
}

int DirectionalBins::bin_of(const glm::vec3& d) const {
  const glm::vec2 uv = octahedral_uv(d);
  const int x = std::clamp(static_cast<int>(uv.x * static_cast<float>(n_)), 0, n_ - 1);
  const int y = std::clamp(static_cast<int>(uv.y * static_cast<float>(n_)), 0, n_ - 1);
  return y * n_ + x;
}

}  // namespace gi
