#pragma once
// What the renderer and a GI system accept from a game at run time, frame by frame: a light
// or a drawn object whose world transform or light values went non-finite or absurd (a
// script dividing by zero, a physics explosion) is skipped for as long as it stays so,
// never drawn or lit with NaN. Each returns nullptr when the value is usable, else why not.
//   if (const char* why = engine::unusable_world_matrix(wt.matrix)) { warn_once(e, why); return; }
//
// Limits (docs/reliability.md): world coordinates within +-1e6 m (1000 km); every axis of a
// transform scaled by 1e-6..1e6; light intensity and colour x intensity finite, >= 0 and at
// most 1e15 (what the glTF reader refuses beyond); range >= 0; cone angles in [0, pi/2];
// a sun's angular radius in [0, pi/4]; area-light sides in 1e-6..1e6 m.

#include <engine/components.h>

#include <cmath>
#include <glm/glm.hpp>

namespace engine {

inline constexpr float kMaxWorldCoordinate = 1e6f;  ///< Metres from the origin.
inline constexpr float kMinAxisScale = 1e-6f;       ///< Length of a transform's axis.
inline constexpr float kMaxAxisScale = 1e6f;
inline constexpr float kMaxRuntimeLightValue = 1e15f;  ///< Intensity, and colour x intensity.

inline const char* unusable_world_matrix(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return "its world transform is not finite";
  for (int r = 0; r < 3; ++r)
    if (std::abs(m[3][r]) > kMaxWorldCoordinate) return "it is placed more than 1e6 m from the origin";
  for (int c = 0; c < 3; ++c) {
    const float len = glm::length(glm::vec3(m[c]));
    if (!(len >= kMinAxisScale && len <= kMaxAxisScale)) return "its transform scales an axis outside 1e-6..1e6";
  }
  return nullptr;
}

inline const char* unusable_light(const Light& l) {
  if (!std::isfinite(l.intensity) || l.intensity < 0.0f || l.intensity > kMaxRuntimeLightValue)
    return "its intensity is not a finite number in [0, 1e15]";
  for (int i = 0; i < 3; ++i) {
    const float c = l.color[i];
    if (!std::isfinite(c) || c < 0.0f || !(c * l.intensity <= kMaxRuntimeLightValue))
      return "its colour is not finite and non-negative, or colour x intensity exceeds 1e15";
  }
  if (!std::isfinite(l.range_m) || l.range_m < 0.0f) return "its range is not a finite number >= 0";
  constexpr float kHalfPi = 1.57079633f;
  if (!(l.inner_cone_rad >= 0.0f && l.inner_cone_rad <= kHalfPi && l.outer_cone_rad >= 0.0f &&
        l.outer_cone_rad <= kHalfPi))
    return "its cone angles are not in [0, pi/2]";
  if (!(l.angular_radius_rad >= 0.0f && l.angular_radius_rad <= 0.7853982f))
    return "its angular radius is not in [0, pi/4]";
  if (l.type == LightType::Area)
    for (int i = 0; i < 2; ++i)
      if (!(l.area_size_m[i] >= kMinAxisScale && l.area_size_m[i] <= kMaxAxisScale))
        return "its area size is not in 1e-6..1e6 m";
  return nullptr;
}

/// A light entity usable this frame: its values and its world transform.
inline const char* unusable_light(const Light& l, const glm::mat4& world) {
  if (const char* why = unusable_light(l)) return why;
  return unusable_world_matrix(world);
}

}  // namespace engine
