#pragma once
// The sky: radiance of the directions no geometry covers (docs/scene-format.md, "The gi
// scene extras"). A uniform part plus an optional gradient over the elevation, y up:
//   L(d) = uniform + horizon + (zenith - horizon) * d.y      for d.y >= 0
//   L(d) = uniform + horizon + (ground - horizon) * (-d.y)   for d.y <  0
// i.e. linear in the sine of the elevation on each hemisphere, continuous at the horizon.
// Energy: an unoccluded floor facing up receives E_up = pi uniform + pi/3 horizon + 2 pi/3
// zenith (sky_irradiance_up); the mean radiance over all directions is uniform + (2 horizon +
// zenith + ground) / 4 (sky_mean_radiance), so a closed room's furnace sees that.
//   engine::SkyGradient g{.zenith = {0.2f, 0.4f, 1.0f}, .horizon = {0.8f, 0.9f, 1.0f}, .ground = {0.1f, 0.1f, 0.1f}};
//   glm::vec3 l = engine::sky_radiance(uniform, g, glm::normalize(dir));

#include <cmath>
#include <optional>
#include <string_view>

#include <glm/glm.hpp>

namespace engine {

/// Radiance (W/(m^2 sr)) of the straight-up, horizontal and straight-down directions; all
/// zero: no gradient.
struct SkyGradient {
  glm::vec3 zenith{0.0f};
  glm::vec3 horizon{0.0f};
  glm::vec3 ground{0.0f};

  bool empty() const { return zenith == glm::vec3(0.0f) && horizon == glm::vec3(0.0f) && ground == glm::vec3(0.0f); }
  bool operator==(const SkyGradient&) const = default;
};

/// Radiance of direction `d` (unit length, pointing away from the scene) of the sky made of
/// `uniform` plus `gradient`.
inline glm::vec3 sky_radiance(const glm::vec3& uniform, const SkyGradient& gradient, const glm::vec3& d) {
  const float y = glm::clamp(d.y, -1.0f, 1.0f);
  const glm::vec3 pole = y >= 0.0f ? gradient.zenith : gradient.ground;
  return uniform + gradient.horizon + (pole - gradient.horizon) * glm::abs(y);
}

/// Whether the sky sends any light.
inline bool sky_lit(const glm::vec3& uniform, const SkyGradient& gradient) {
  const glm::vec3 zero(0.0f);
  return glm::any(glm::greaterThan(uniform, zero)) || glm::any(glm::greaterThan(gradient.zenith, zero)) ||
         glm::any(glm::greaterThan(gradient.horizon, zero)) || glm::any(glm::greaterThan(gradient.ground, zero));
}

/// Mean radiance over the sphere of directions (|y| is uniform on [0, 1] over a hemisphere,
/// so each hemisphere's mean of h + (p - h)|y| is (h + p) / 2): uniform + (2 horizon + zenith
/// + ground) / 4.
inline glm::vec3 sky_mean_radiance(const glm::vec3& uniform, const SkyGradient& gradient) {
  return uniform + (2.0f * gradient.horizon + gradient.zenith + gradient.ground) * 0.25f;
}

/// Exact irradiance (W/m^2) of an unoccluded surface facing straight up (it sees the upper
/// hemisphere only): E = 2 pi int_0^1 L(mu) mu dmu = pi uniform + pi/3 horizon + 2 pi/3 zenith.
inline glm::vec3 sky_irradiance_up(const glm::vec3& uniform, const SkyGradient& gradient) {
  constexpr float pi = 3.14159265358979f;
  return pi * uniform + (pi / 3.0f) * gradient.horizon + (2.0f * pi / 3.0f) * gradient.zenith;
}

/// Exact irradiance (W/m^2) of an unoccluded surface of unit normal n. The sky is
/// uniform + horizon + (zenith - horizon) max(d.y, 0) + (ground - horizon) max(-d.y, 0), and
/// the integral over the sphere of max(d.a, 0) max(d.n, 0) for unit a, n an angle t apart is
/// K(t) = 2/3 ((pi - t) cos t + sin t), so with t = acos(n.y):
///   E = pi (uniform + horizon) + (zenith - horizon) K(t) + (ground - horizon) K(pi - t).
/// The renderer's forward.frag.glsl evaluates the same.
inline float sky_kink_irradiance(float t) {
  constexpr float pi = 3.14159265358979f;
  return (2.0f / 3.0f) * ((pi - t) * std::cos(t) + std::sin(t));
}
inline glm::vec3 sky_irradiance(const glm::vec3& uniform, const SkyGradient& gradient, const glm::vec3& n) {
  constexpr float pi = 3.14159265358979f;
  const float t = std::acos(glm::clamp(n.y, -1.0f, 1.0f));
  return pi * (uniform + gradient.horizon) + (gradient.zenith - gradient.horizon) * sky_kink_irradiance(t) +
         (gradient.ground - gradient.horizon) * sky_kink_irradiance(pi - t);
}

/// A sky as the command-line tools take it (`--sky` of gi-bake, gi-reference and gi_demo;
/// docs/scene-format.md): "R,G,B" a uniform sky, or "zenith:R,G,B;horizon:R,G,B;ground:R,G,B"
/// a gradient (the three keys in any order, each once); finite radiances >= 0, W/(m^2 sr).
/// Either form replaces a scene's whole sky: the uniform form has no gradient, the gradient
/// form no uniform part.
struct SkyText {
  glm::vec3 uniform{0.0f};
  SkyGradient gradient;
};
/// Parses `text`; nullopt when it is malformed.
std::optional<SkyText> parse_sky_text(std::string_view text);
inline constexpr const char* kSkyTextUsage =
    "R,G,B or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B': finite radiances >= 0, W/(m^2 sr)";

}  // namespace engine
