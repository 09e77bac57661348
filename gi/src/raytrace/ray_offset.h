#pragma once
// Spawning secondary rays without self-intersection, independent of the scene's scale:
// Wächter and Binder 2019, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray
// Tracing Gems, ch. 6). The origin moves along the geometric normal by a few ulps of its
// own coordinates (integer arithmetic on the float bits), or by a tiny fixed amount near 0.
//   glm::vec3 o = gi::offset_ray_origin(hit_point, facing_normal);
//   caster.occluded(gi::Ray{.origin = o, .direction = to_light, .t_max = 1.0f});

#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace gi {

/// `p` moved off its surface to the side `n` points to (n need not be unit length but must
/// not be zero; a unit normal gives the paper's offsets).
inline glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n) {
  constexpr float kOrigin = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  glm::vec3 out;
  for (int i = 0; i < 3; ++i) {
    const auto of = static_cast<std::int32_t>(kIntScale * n[i]);
    const std::int32_t bits = std::bit_cast<std::int32_t>(p[i]);
    const float moved = std::bit_cast<float>(bits + (p[i] < 0.0f ? -of : of));
    out[i] = std::fabs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : moved;
  }
  return out;
}

}  // namespace gi
