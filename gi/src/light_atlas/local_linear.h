#pragma once
// Local linear fits for the light atlas's world-space filters (atlas_denoise.h,
// texel_filter.h): a weighted mean of a texel's neighbours turned into the intercept of a
// weighted least-squares plane through them, which keeps a gradient's value at the texel
// where a kernel cut off at a chart's edge (or tilted by its value weights) would read the
// value at the kernel's centre of mass instead.
//   std::vector<gi::Neighbour> taken = ...;  // weights w_j, offsets in tangent_frame(n)
//   gi::to_linear_weights(0.0f, taken);       // now the fit's equivalent weights

#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// A neighbour a filter takes: its texel, weight, and offset in the texel's tangent plane (in
/// the filter's units of length).
struct Neighbour {
  std::uint32_t j;
  float w;
  glm::vec2 uv;
};

/// Columns 0 and 1: two unit tangents of the plane with unit normal `n`; column 2: `n`.
glm::mat3 tangent_frame(const glm::vec3& n);

/// Turns the weights w_j of a local mean into the equivalent weights of a local linear fit's
/// intercept: l_j = w_j (1, u_j, v_j) S^-1 (1, 0, 0)^T with S = sum w_j (1, u_j, v_j)^T (1,
/// u_j, v_j) + ridge W diag(0, 1, 1), W = sum w_j. The l_j sum to 1 (a constant is kept
/// exactly), and a linear trend is taken out; where the offsets span no plane (a chart one
/// texel wide) the ridge (and a 1e-9 floor) keeps S invertible, and the fit falls back
/// towards the mean along the missing direction. Some l_j may be negative.
void to_linear_weights(float ridge, std::vector<Neighbour>& taken);

}  // namespace gi
