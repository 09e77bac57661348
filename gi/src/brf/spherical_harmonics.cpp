#include "brf/spherical_harmonics.h"

#include <cmath>
#include <numbers>

namespace gi {

std::array<float, kMaxShCoefficients> sh_basis(const glm::vec3& w) {
  const float x = w.x, y = w.y, z = w.z;
  std::array<float, kMaxShCoefficients> c{};
  // Band 0..3 constants: sqrt((2l+1)/(4 pi) (l-|m|)!/(l+|m|)!) with the sqrt(2) of real SH.
  c[0] = 0.282094792f;
  c[1] = 0.488602512f * y;
  c[2] = 0.488602512f * z;
  c[3] = 0.488602512f * x;
  c[4] = 1.092548431f * x * y;
  c[5] = 1.092548431f * y * z;
  c[6] = 0.315391565f * (3.0f * z * z - 1.0f);
  c[7] = 1.092548431f * x * z;
  c[8] = 0.546274215f * (x * x - y * y);
  c[9] = 0.590043589f * y * (3.0f * x * x - y * y);
  c[10] = 2.890611442f * x * y * z;
  c[11] = 0.457045799f * y * (5.0f * z * z - 1.0f);
  c[12] = 0.373176333f * z * (5.0f * z * z - 3.0f);
  c[13] = 0.457045799f * x * (5.0f * z * z - 1.0f);
  c[14] = 1.445305721f * z * (x * x - y * y);
  c[15] = 0.590043589f * x * (x * x - 3.0f * y * y);
  return c;
}

std::array<float, kMaxShCoefficients> sh_clamped_cosine(const glm::vec3& n, int bands) {
  // Zonal coefficients of max(0, cos theta): A_l = sqrt(4 pi / (2l + 1)) x z_l, with the
  // rotation to n done by evaluating Y_lm(n) (Ramamoorthi and Hanrahan 2001).
  constexpr float kPi = std::numbers::pi_v<float>;
  const float band[kMaxShBands] = {kPi, 2.0f * kPi / 3.0f, kPi / 4.0f, 0.0f};
  const std::array<float, kMaxShCoefficients> y = sh_basis(n);
  std::array<float, kMaxShCoefficients> out{};
  for (int l = 0; l < bands && l < kMaxShBands; ++l)
    for (int m = -l; m <= l; ++m) {
      const auto i = static_cast<std::size_t>(l * (l + 1) + m);
      out[i] = band[l] * y[i];
    }
  return out;
}

std::array<float, kMaxShCoefficients> sh_cosine(const glm::vec3& n) {
  // n . w = (4 pi / 3) sum_m Y_1m(n) Y_1m(w): band 1 only, twice the clamped lobe's.
  const std::array<float, kMaxShCoefficients> y = sh_basis(n);
  std::array<float, kMaxShCoefficients> out{};
  for (std::size_t i = 1; i < 4; ++i) out[i] = 4.0f * std::numbers::pi_v<float> / 3.0f * y[i];
  return out;
}

}  // namespace gi
