#pragma once
// Falloff rules of punctual lights shared by the renderer's twins on the CPU (the reference
// path tracer, the bakers): the glTF KHR_lights_punctual range window and the spot cone's
// smoothstep, exactly as engine/shaders/lighting_common.glsl evaluates them.

#include <algorithm>

#include <glm/glm.hpp>

namespace gi {

/// (1 - (d/range)^4)^2 clamped to [0, 1]; range <= 0: no window.
inline float range_window(float distance_m, float range_m) {
  if (range_m <= 0.0f) return 1.0f;
  const float r = distance_m / range_m;
  const float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
  return w * w;
}

inline float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

/// Spot cone factor for unit `to_light` (from the lit point to the light) and the light's
/// unit emission axis: smoothstep between the outer and inner cone, a hard edge when they
/// coincide.
inline float spot_cone(const glm::vec3& axis, float cos_outer, float cos_inner, const glm::vec3& to_light) {
  const float cos_axis = glm::dot(-to_light, axis);
  if (cos_inner - cos_outer > 1e-5f) return smoothstep(cos_outer, cos_inner, cos_axis);
  return cos_axis >= cos_outer ? 1.0f : 0.0f;
}

}  // namespace gi
