#pragma once
// Linear RGB samples on a grid (camera pixels or light-atlas texels) with an optional
// validity mask: the data every accuracy metric and every sweep run compares.
//   gi::RgbField f = gi::RgbField::filled(64, 64, 0.5f);
//   f.valid.assign(f.count(), 1);  // mask texels that are not covered by any chart with 0

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// width x height elements, row-major, 3 linear floats (R, G, B) each; radiance or
/// irradiance, the unit is whatever the producer states (metrics are scale-free or say so).
struct RgbField {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;           ///< 3 * width * height values.
  std::vector<std::uint8_t> valid;  ///< Empty (every element valid) or width * height flags, nonzero = valid.
  /// Empty, or 3 * width * height values: the sampling variance of each value as an estimate
  /// of its expectation (a Monte Carlo reference's own noise, Var of the mean). Lets
  /// compare_rgb estimate the error against the noise-free truth (error_metrics.h).
  std::vector<float> variance;

  /// Number of elements (pixels / texels).
  std::size_t count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  /// True when element i takes part in comparisons.
  bool is_valid(std::size_t i) const { return valid.empty() || valid[i] != 0; }
  /// True when the vector sizes agree with width and height.
  bool consistent() const {
    return width >= 0 && height >= 0 && rgb.size() == 3 * count() && (valid.empty() || valid.size() == count()) &&
           (variance.empty() || variance.size() == 3 * count());
  }
  /// True when two fields can be compared element by element (same width and height).
  bool same_layout(const RgbField& other) const { return width == other.width && height == other.height; }

  /// A width x height field with every channel set to `value` and no mask.
  static RgbField filled(int w, int h, float value) {
    RgbField f;
    f.width = w;
    f.height = h;
    f.rgb.assign(3 * f.count(), value);
    return f;
  }

  /// A width x height field from RGB triples (row-major, width * height of them), a mask
  /// (empty: every element valid) and per-channel sampling variances (empty: unknown).
  /// Precondition: the sizes agree.
  static RgbField from_texels(int w, int h, std::span<const glm::vec3> values, std::vector<std::uint8_t> mask = {},
                              std::span<const glm::vec3> variances = {}) {
    RgbField f;
    f.width = w;
    f.height = h;
    f.valid = std::move(mask);
    f.rgb.reserve(3 * values.size());
    for (const glm::vec3& v : values) f.rgb.insert(f.rgb.end(), {v.x, v.y, v.z});
    f.variance.reserve(3 * variances.size());
    for (const glm::vec3& v : variances) f.variance.insert(f.variance.end(), {v.x, v.y, v.z});
    return f;
  }
};

}  // namespace gi
