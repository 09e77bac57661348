#pragma once
// Scalar summaries of a linear RGB colour, one definition for every baker and the runtime.
// Both luminance variants use Rec. 709 / sRGB primaries' weights; the float one computes in
// float, the double one in double, so each caller keeps the arithmetic it was written with
// (bakes are byte-identical across builds: do not mix them).
//   float y = gi::luminance(albedo);                 // float, as the bakers weigh paths
//   double yd = gi::luminance(double{c.x}, double{c.y}, double{c.z});  // accuracy figures

#include <algorithm>
#include <glm/vec3.hpp>

namespace gi {

/// Luminance of linear RGB `c`, in float: 0.2126 R + 0.7152 G + 0.0722 B.
inline float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/// Luminance of linear RGB (r, g, b), in double: 0.2126 r + 0.7152 g + 0.0722 b.
inline double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

/// The largest of the three channels (Russian roulette's survival probability, an albedo's bound).
inline float max_component(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

}  // namespace gi
