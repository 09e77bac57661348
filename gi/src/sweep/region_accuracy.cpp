#include "sweep/region_accuracy.h"

#include <engine/check.h>
#include <gi/error_metrics.h>
#include <gi/rgb_field.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace gi {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

RgbField rgb_field(const engine::ImageRgbaF& image, std::span<const std::uint8_t> mask) {
  RgbField f;
  f.width = image.width;
  f.height = image.height;
  f.rgb.resize(3 * f.count());
  for (std::size_t i = 0; i < f.count(); ++i)
    for (std::size_t c = 0; c < 3; ++c) f.rgb[3 * i + c] = image.pixels[4 * i + c];
  f.valid.assign(mask.begin(), mask.end());
  return f;
}

}  // namespace

RegionAccuracy measure_region(const std::string& name, const engine::ImageRgbaF& frame, const engine::ImageRgbaF& truth,
                              std::span<const float> truth_variance, std::span<const std::uint8_t> mask) {
  const std::size_t n = static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height);
  GI_EXPECTS(frame.width == truth.width && frame.height == truth.height, "frame and truth must be the same size");
  GI_EXPECTS(frame.pixels.size() == 4 * n && truth.pixels.size() == 4 * n, "RGBA images of width x height");
  GI_EXPECTS(truth_variance.size() == 3 * n && mask.size() == n, "3 variances and a mask flag per pixel");

  RegionAccuracy a;
  a.name = name;
  double sum_frame = 0.0, sum_truth = 0.0, sum_variance = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    ++a.pixels;
    const float* f = &frame.pixels[4 * i];
    const float* t = &truth.pixels[4 * i];
    const float* v = &truth_variance[3 * i];
    sum_frame += luminance(f[0], f[1], f[2]);
    sum_truth += luminance(t[0], t[1], t[2]);
    // The luminance's variance, the channels taken as independent (their noise is not,
    // being one path's: this is a floor of the bias's noise, not a bound).
    sum_variance += 0.2126 * 0.2126 * double{v[0]} + 0.7152 * 0.7152 * double{v[1]} + 0.0722 * 0.0722 * double{v[2]};
  }
  const double count = static_cast<double>(std::max<std::size_t>(a.pixels, 1));
  a.frame_luminance = sum_frame / count;
  a.truth_luminance = sum_truth / count;
  const bool lit = a.pixels > 0 && sum_truth > 0.0;
  a.bias = lit ? sum_frame / sum_truth - 1.0 : kNaN;
  a.bias_noise = lit ? (sum_frame / sum_truth) * std::sqrt(sum_variance) / sum_truth : kNaN;

  RgbField ref = rgb_field(truth, mask);
  ref.variance.assign(truth_variance.begin(), truth_variance.end());
  const ErrorReport e = compare_rgb(rgb_field(frame, mask), ref);
  a.rel_rmse = e.rel_rmse;
  a.truth_rel_rmse = e.truth_rel_rmse;
  a.reference_noise = e.reference_noise;
  a.problem = e.problem;
  if (a.problem.empty() && !lit) a.problem = "the truth is black over these pixels";
  return a;
}

engine::ImageRgba8 ratio_image(const FrameTruthReport& report, float stops) {
  GI_EXPECTS(stops > 0.0f, "ratio_image needs stops > 0");
  const engine::ImageRgbaF& frame = report.frame;
  const std::size_t n = static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height);
  GI_EXPECTS(report.truth.pixels.size() == 4 * n && report.region_of_pixel.size() == n,
             "a report whose images and region map have the frame's size");
  // Near-black pixels compare with a floor of a thousandth of the frame's mean truth, so
  // that two dark pixels read as equal rather than as a wild ratio.
  const double floor = 1e-3 * std::max(report.overall.truth_luminance, 1e-12);
  engine::ImageRgba8 out{.width = frame.width, .height = frame.height, .pixels = {}};
  out.pixels.assign(4 * n, 255);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* o = &out.pixels[4 * i];
    if (report.region_of_pixel[i] == kBackgroundPixel) {
      o[0] = o[1] = o[2] = 128;
      continue;
    }
    const float* f = &frame.pixels[4 * i];
    const float* t = &report.truth.pixels[4 * i];
    const double ratio = (luminance(f[0], f[1], f[2]) + floor) / (luminance(t[0], t[1], t[2]) + floor);
    const double s =
        std::isfinite(ratio) && ratio > 0.0 ? std::clamp(std::log2(ratio) / double{stops}, -1.0, 1.0) : 1.0;
    const auto fade = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - std::fabs(s))));
    o[0] = s < 0.0 ? fade : 255;
    o[1] = fade;
    o[2] = s > 0.0 ? fade : 255;
  }
  return out;
}

}  // namespace gi
