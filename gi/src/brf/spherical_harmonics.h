#pragma once
// Real spherical harmonics up to band 3 (16 coefficients; band l has 2l + 1), orthonormal
// over the sphere, in the common "l, m" order: index = l (l + 1) + m. Used to store the
// basis radiance of basis radiance fields (Iwasaki et al. §4.3) compactly.
//   std::array<float, 16> y = gi::sh_basis(direction);   // unit direction
//   float f = gi::sh_dot(coeffs_a, coeffs_b, 9);          // integral of the product (3 bands)

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

inline constexpr int kMaxShBands = 4;
inline constexpr int kMaxShCoefficients = kMaxShBands * kMaxShBands;

/// Y_lm(w) for l < 4 at a unit direction w (z up).
std::array<float, kMaxShCoefficients> sh_basis(const glm::vec3& w);

/// sum_i a_i b_i over the first `n` coefficients: the integral over the sphere of the
/// product of the two functions (the basis is orthonormal).
inline float sh_dot(std::span<const float> a, std::span<const float> b, std::size_t n) {
  float s = 0.0f;
  for (std::size_t i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

/// Coefficients of the clamped cosine max(0, n . w) around unit n (zonal: pi, 2pi/3, pi/4
/// per band 0..2, 0 for band 3), for `bands` bands: dotted with a radiance's coefficients
/// it gives the irradiance.
std::array<float, kMaxShCoefficients> sh_clamped_cosine(const glm::vec3& n, int bands);

/// Coefficients of the unclamped cosine n . w (band 1 only: (4 pi / 3) Y_1m(n)). For
/// radiance arriving only from directions with n . w > 0 (a source wholly in front of the
/// receiver's tangent plane) its product with the radiance is the exact irradiance: no
/// truncation of the clamped lobe's higher bands, no ringing.
std::array<float, kMaxShCoefficients> sh_cosine(const glm::vec3& n);

/// A rotation of SH coefficients (bands < 4): for f given by `in` in one frame, apply()
/// gives the coefficients of the same function seen in another frame, f(R^T w), where R
/// (orthonormal) maps the first frame's directions into the second's. Rotations keep bands
/// apart, so each band is a (2l + 1)^2 block, built by evaluating the basis at 2l + 1
/// fixed directions d_n and at R^T d_n: M_l = Y_l(D)^-1 Y_l(R^T D) (exact for band-limited
/// functions; the direction sets are chosen well conditioned).
///   gi::ShRotation rot(frame_to_world);       // columns: the frame's axes in world space
///   rot.apply(local_coeffs, world_coeffs, 4);
class ShRotation {
 public:
  explicit ShRotation(const glm::mat3& r);
  /// out[0 .. bands^2) from in[0 .. bands^2); in and out must not overlap.
  void apply(std::span<const float> in, std::span<float> out, int bands) const;
  /// The band-l block, row-major ((2l + 1) x (2l + 1)): out_l = block(l) in_l.
  const float* block(int l) const { return m_.data() + kOffset[l]; }

 private:
  static constexpr std::size_t kOffset[kMaxShBands] = {0, 1, 10, 35};
  std::array<float, 84> m_{};
};

/// The fixed construction behind ShRotation, for twins of it (the GPU pass): block(l) =
/// pinv[l] Y_l(R^T directions), pinv[l] row-major (2l + 1) x directions.size() (band 0 empty).
struct ShRotationTables {
  std::vector<glm::vec3> directions;
  std::array<std::vector<float>, kMaxShBands> pinv;
};
const ShRotationTables& sh_rotation_tables();

}  // namespace gi
