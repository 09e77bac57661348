#pragma once
// The engine's display transform on the CPU, for metrics on what the player sees:
// exposure, the ACES filmic fit by Narkowicz (2015) clamped to [0, 1], then the exact sRGB
// encoding. Mirrors engine/shaders/tonemap.frag.glsl (renderer.h documents it).
//   float ldr = engine::display_tonemap(radiance.r, /*exposure=*/1.0f);  // in [0, 1], sRGB-encoded
//   int byte = static_cast<int>(ldr * 255.0f + 0.5f);

#include <algorithm>
#include <cmath>

namespace engine {

/// ACES fitted (Narkowicz): x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to [0, 1].
inline double aces_narkowicz(double x) {
  const double y = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
  return std::clamp(y, 0.0, 1.0);
}

/// The sRGB transfer function for a linear value in [0, 1].
inline double srgb_encode(double c) { return c < 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; }

/// One linear channel to its displayed value in [0, 1]: srgb(aces(max(x, 0) * exposure)),
/// clamped to [0, 1] as the 8-bit target does.
/// NaN stays NaN (callers count non-finite input before tonemapping).
inline double display_tonemap(double linear, double exposure) {
  if (std::isnan(linear)) return linear;
  return std::clamp(srgb_encode(aces_narkowicz(std::max(linear, 0.0) * exposure)), 0.0, 1.0);
}

}  // namespace engine
