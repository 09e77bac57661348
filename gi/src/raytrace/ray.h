#pragma once
// Rays and hits of the ray-tracing core (world space, metres).

#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace gi {

struct Ray {
  glm::vec3 origin{0.0f};
  float t_min = 0.0f;
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  ///< Need not be normalized; t is in its units.
  float t_max = std::numeric_limits<float>::infinity();
};

inline constexpr std::uint32_t kNoHit = 0xffffffffu;

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  std::uint32_t geometry = kNoHit;   ///< Index into RtSceneData::geometries.
  std::uint32_t instance = kNoHit;   ///< Index into RtSceneData::instances.
  std::uint32_t primitive = kNoHit;  ///< Triangle index within the geometry.
  glm::vec2 barycentric{0.0f};       ///< (u, v): p = (1-u-v) p0 + u p1 + v p2.
  glm::vec3 geometric_normal{0.0f};  ///< Unnormalized, world space, from the triangle winding.

  bool valid() const { return geometry != kNoHit; }
};

}  // namespace gi
