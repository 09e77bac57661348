#include "core/polygon_form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace gi {

float polygon_form_factor(const glm::vec3& p, const glm::vec3& n, std::span<const glm::vec3> polygon) {
  constexpr std::size_t kMaxCorners = 8;
  if (polygon.size() < 3 || polygon.size() > kMaxCorners) return 0.0f;
  // Clip to the half-space in front of p (Sutherland-Hodgman against one plane: a convex
  // polygon gains at most one corner).
  std::array<glm::vec3, kMaxCorners + 1> clipped{};
  std::size_t count = 0;
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    const glm::vec3& a = polygon[k];
    const glm::vec3& b = polygon[(k + 1) % polygon.size()];
    const float da = glm::dot(n, a - p), db = glm::dot(n, b - p);
    if (da > 0.0f) clipped[count++] = a;
    if ((da > 0.0f) != (db > 0.0f)) clipped[count++] = a + (b - a) * (da / (da - db));
  }
  if (count < 3) return 0.0f;
  // Lambert: the sum over edges of the angle they subtend times n . (the edge plane's unit
  // normal), over 2 pi; the winding gives its sign, and every corner is in front of p.
  double sum = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const glm::vec3 a = clipped[k] - p, b = clipped[(k + 1) % count] - p;
    const float la = glm::length(a), lb = glm::length(b);
    if (!(la > 0.0f) || !(lb > 0.0f)) continue;
    const glm::vec3 c = glm::cross(a / la, b / lb);
    const float len = glm::length(c);
    if (!(len > 0.0f)) continue;
    const float angle = std::atan2(len, glm::dot(a / la, b / lb));
    sum += static_cast<double>(angle * glm::dot(n, c / len));
  }
  return std::clamp(static_cast<float>(std::abs(sum) / (2.0 * std::numbers::pi)), 0.0f, 1.0f);
}

}  // namespace gi
