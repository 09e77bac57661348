#include "brf/spherical_harmonics.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Dense>

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

namespace {

// Fixed directions D (a Fibonacci spiral, turned off the axes so no symmetry of the basis
// meets them) and, per band l >= 1, the least-squares inverse of the band's basis matrix
// over them, (Y_l^T Y_l)^-1 Y_l^T, in double precision once. More directions than 2l + 1
// keep every band well conditioned; for band-limited functions the fit is exact.
struct BandFrames {
  static constexpr int kDirections = 26;
  std::vector<glm::vec3> dirs;
  std::array<Eigen::MatrixXd, kMaxShBands> pinv;
  BandFrames() {
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int n = 0; n < kDirections; ++n) {
      const double z = 1.0 - (2.0 * n + 1.0) / kDirections;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double phi = golden * n + 0.3;
      const double x = r * std::cos(phi), y = r * std::sin(phi);
      dirs.push_back(
          glm::normalize(glm::vec3(static_cast<float>(x), static_cast<float>(y * std::cos(0.4) - z * std::sin(0.4)),
                                   static_cast<float>(y * std::sin(0.4) + z * std::cos(0.4)))));
    }
    for (int l = 1; l < kMaxShBands; ++l) {
      const int count = 2 * l + 1;
      Eigen::MatrixXd y(kDirections, count);
      for (int n = 0; n < kDirections; ++n) {
        const auto b = sh_basis(dirs[static_cast<std::size_t>(n)]);
        for (int m = 0; m < count; ++m) y(n, m) = static_cast<double>(b[static_cast<std::size_t>(l * l + m)]);
      }
      pinv[static_cast<std::size_t>(l)] = (y.transpose() * y).inverse() * y.transpose();
    }
  }
};

const BandFrames& band_frames() {
  static const BandFrames frames;
  return frames;
}

}  // namespace

const ShRotationTables& sh_rotation_tables() {
  static const ShRotationTables tables = [] {
    const BandFrames& frames = band_frames();
    ShRotationTables t;
    t.directions = frames.dirs;
    for (int l = 1; l < kMaxShBands; ++l) {
      const Eigen::MatrixXd& p = frames.pinv[static_cast<std::size_t>(l)];
      std::vector<float>& out = t.pinv[static_cast<std::size_t>(l)];
      for (Eigen::Index a = 0; a < p.rows(); ++a)
        for (Eigen::Index n = 0; n < p.cols(); ++n) out.push_back(static_cast<float>(p(a, n)));
    }
    return t;
  }();
  return tables;
}

ShRotation::ShRotation(const glm::mat3& r) {
  const BandFrames& frames = band_frames();
  const glm::mat3 rt = glm::transpose(r);
  std::array<std::array<float, kMaxShCoefficients>, BandFrames::kDirections> yr;
  for (std::size_t n = 0; n < yr.size(); ++n) yr[n] = sh_basis(rt * frames.dirs[n]);
  m_[0] = 1.0f;
  for (int l = 1; l < kMaxShBands; ++l) {
    const int count = 2 * l + 1;
    const Eigen::MatrixXd& pinv = frames.pinv[static_cast<std::size_t>(l)];
    for (int a = 0; a < count; ++a)
      for (int c = 0; c < count; ++c) {
        double s = 0.0;
        for (int n = 0; n < BandFrames::kDirections; ++n)
          s += pinv(a, n) * static_cast<double>(yr[static_cast<std::size_t>(n)][static_cast<std::size_t>(l * l + c)]);
        m_[kOffset[l] + static_cast<std::size_t>(a * count + c)] = static_cast<float>(s);
      }
  }
}

void ShRotation::apply(std::span<const float> in, std::span<float> out, int bands) const {
  out[0] = in[0];
  for (int l = 1; l < bands && l < kMaxShBands; ++l) {
    const int count = 2 * l + 1;
    const float* b = block(l);
    for (int a = 0; a < count; ++a) {
      float s = 0.0f;
      for (int c = 0; c < count; ++c) s += b[a * count + c] * in[static_cast<std::size_t>(l * l + c)];
      out[static_cast<std::size_t>(l * l + a)] = s;
    }
  }
}

}  // namespace gi
