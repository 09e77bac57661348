#pragma once
// Step 4b of the texel gather (texel_gather.h): a guided denoiser of the gathered light in
// world space, across chart borders. Edge-avoiding a-trous (Dammertz et al. 2010) with a
// variance-guided value weight (SVGF, Schied et al. 2017): `passes` passes of a sparse
// kernel whose step doubles each pass (1, 2, 4, ... texels); a neighbour's weight falls with
// the angle between the normals, with its distance off the texel's plane, and with the
// difference of the two values in units of the standard deviation of that difference, so an
// edge the estimate resolves (a sun-bounce gradient, a shadow) stays and noise goes.
// Optionally (`outlier_sigmas`, off by default), before the passes, a texel far above its
// neighbours (a gather whose few rays hit a bright patch the others missed) is clamped to
// their mean + `outlier_sigmas` of their spread: its own variance, large, would otherwise
// let the passes spread it into a blotch.
//   gi::denoise_world(texels, work, hidden, variance, texel_m, {.passes = 4}, pool, {&indirect, &sky});

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "core/thread_pool.h"
#include "transport/static_scene.h"

namespace gi {

struct DenoiseSettings {
  int passes = 4;  ///< A-trous passes; pass k's step is 2^k texels (0: no denoising).
  /// Value weight exp(-(l_i - l_j)^2 / (2 value_sigma^2 var(l_i - l_j))).
  float value_sigma = 2.0f;
  float normal_power = 64.0f;  ///< Normal weight max(0, n_i . n_j)^normal_power.
  /// The clamp before the passes: a texel's luminance at most the mean + outlier_sigmas
  /// standard deviations of its co-planar neighbours' within 2.5 texels, their brightest left
  /// out (0: no clamp). Off by default: at 3 it removes the crate room's blotches but costs
  /// Dabrovic Sponza 1.5 points of its indirect-dominated error (docs/light_atlas.md).
  float outlier_sigmas = 0.0f;
  /// Local linear instead of local constant: each pass fits value = a + b . (offset in the
  /// texel's tangent plane) to the weighted neighbours and keeps a (weighted least squares,
  /// the slope b penalised by `slope_ridge` x the summed weight, in units of the pass's step).
  /// A kernel cut off at a chart's edge, or lying on a gradient, then estimates the value at
  /// the texel rather than at the kernel's centre of mass (the boundary bias of local
  /// averaging; local linear regression has none to first order). Negative: off.
  float slope_ridge = -1.0f;
};

/// Denoises the fields `fields` (each per atlas texel, W/m^2) together over the texels of
/// `work` that are not `hidden`, guided by the luminance of their sum, whose per-texel
/// variance (of the estimate, (W/m^2)^2) is `variance`; `variance` is updated to the
/// variance of the denoised sum as the passes propagate it. Hidden texels keep their values
/// and are read by nobody. Texel i's atlas pixel (i % texels.width, i / texels.width) places
/// it on the sparse lattice of each pass. Bit-identical for any thread count.
void denoise_world(const AtlasTexels& texels, std::span<const std::uint32_t> work,
                   const std::vector<std::uint8_t>& hidden, float texel_m, const DenoiseSettings& settings,
                   ThreadPool& pool, std::vector<float>& variance, std::span<std::vector<glm::vec3>* const> fields);

}  // namespace gi
