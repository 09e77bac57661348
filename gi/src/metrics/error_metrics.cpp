#include <engine/check.h>
#include <engine/display_transform.h>
#include <gi/error_metrics.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace gi {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void check_layouts(const RgbField& a, const RgbField& r) {
  GI_EXPECTS(a.consistent(), "approximation: rgb/valid sizes must match width x height");
  GI_EXPECTS(r.consistent(), "reference: rgb/valid sizes must match width x height");
  GI_EXPECTS(a.same_layout(r), "approximation and reference must have the same width and height");
}

bool compared(const RgbField& a, const RgbField& r, std::size_t i) { return a.is_valid(i) && r.is_valid(i); }

double norm3(double x, double y, double z) { return std::sqrt(x * x + y * y + z * z); }

/// Channel value k of a field, widened to double.
double at(const RgbField& f, std::size_t k) { return static_cast<double>(f.rgb[k]); }

}  // namespace

double relative_rmse(const RgbField& a, const RgbField& r, double scale) {
  check_layouts(a, r);
  double err2 = 0.0;
  double ref2 = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.count(); ++i) {
    if (!compared(a, r, i)) continue;
    ++n;
    for (std::size_t c = 0; c < 3; ++c) {
      const double rv = at(r, 3 * i + c);
      const double d = scale * at(a, 3 * i + c) - rv;
      err2 += d * d;
      ref2 += rv * rv;
    }
  }
  if (n == 0 || !std::isfinite(err2) || !std::isfinite(ref2) || ref2 <= 0.0) return kNaN;
  return std::sqrt(err2 / ref2);
}

double max_relative_error(const RgbField& a, const RgbField& r, double floor_eps, double scale) {
  check_layouts(a, r);
  GI_EXPECTS(floor_eps > 0.0, "the max-relative floor must be positive");
  double sum_norm = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.count(); ++i) {
    if (!compared(a, r, i)) continue;
    ++n;
    sum_norm += norm3(at(r, 3 * i), at(r, 3 * i + 1), at(r, 3 * i + 2));
  }
  if (n == 0 || !std::isfinite(sum_norm) || sum_norm <= 0.0) return kNaN;
  const double floor = floor_eps * sum_norm / static_cast<double>(n);
  double worst = 0.0;
  for (std::size_t i = 0; i < a.count(); ++i) {
    if (!compared(a, r, i)) continue;
    const double dr = scale * at(a, 3 * i) - at(r, 3 * i);
    const double dg = scale * at(a, 3 * i + 1) - at(r, 3 * i + 1);
    const double db = scale * at(a, 3 * i + 2) - at(r, 3 * i + 2);
    const double e = norm3(dr, dg, db) / std::max(norm3(at(r, 3 * i), at(r, 3 * i + 1), at(r, 3 * i + 2)), floor);
    if (!std::isfinite(e)) return kNaN;  // std::max would silently drop a NaN
    worst = std::max(worst, e);
  }
  return worst;
}

double tonemapped_psnr_db(const RgbField& a, const RgbField& r, double exposure, double scale) {
  check_layouts(a, r);
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.count(); ++i) {
    if (!compared(a, r, i)) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      const double av = scale * at(a, 3 * i + c);
      const double rv = at(r, 3 * i + c);
      if (!std::isfinite(av) || !std::isfinite(rv)) return kNaN;
      const double d = engine::display_tonemap(av, exposure) - engine::display_tonemap(rv, exposure);
      sum += d * d;
      ++n;
    }
  }
  if (n == 0) return kNaN;
  const double mse = sum / static_cast<double>(n);
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(1.0 / mse);
}

double least_squares_scale(const RgbField& a, const RgbField& r) {
  check_layouts(a, r);
  double ar = 0.0;
  double aa = 0.0;
  for (std::size_t i = 0; i < a.count(); ++i) {
    if (!compared(a, r, i)) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      const double av = at(a, 3 * i + c);
      ar += av * at(r, 3 * i + c);
      aa += av * av;
    }
  }
  if (!std::isfinite(ar) || !std::isfinite(aa)) return kNaN;
  return aa > 0.0 ? ar / aa : 1.0;
}

ErrorReport compare_rgb(const RgbField& a, const RgbField& r, const MetricOptions& options) {
  check_layouts(a, r);
  ErrorReport e;
  double ref2 = 0.0;
  for (std::size_t i = 0; i < a.count(); ++i) {
    if (!compared(a, r, i)) continue;
    ++e.elements_compared;
    for (std::size_t c = 0; c < 3; ++c) {
      const double av = at(a, 3 * i + c);
      const double rv = at(r, 3 * i + c);
      if (!std::isfinite(av)) ++e.nonfinite_approx;
      if (!std::isfinite(rv))
        ++e.nonfinite_reference;
      else
        ref2 += rv * rv;
    }
  }
  if (e.elements_compared == 0) {
    e.problem = "no element is valid in both the output and the reference masks";
  } else if (e.nonfinite_approx > 0 || e.nonfinite_reference > 0) {
    e.problem = std::to_string(e.nonfinite_approx) + " non-finite (NaN/Inf) value(s) in the output, " +
                std::to_string(e.nonfinite_reference) + " in the reference";
  } else if (!(ref2 > 0.0) || !std::isfinite(ref2)) {
    e.problem = "the reference is zero on every compared element: relative error is undefined";
  }
  e.reference_noise = e.truth_rel_rmse = kNaN;
  if (!e.ok()) {
    e.rel_rmse = e.max_rel = e.psnr_db = e.fit_scale = e.fit_rel_rmse = e.fit_max_rel = e.fit_psnr_db = kNaN;
    return e;
  }
  if (!r.variance.empty()) {
    double diff2 = 0.0, var = 0.0;
    for (std::size_t i = 0; i < a.count(); ++i) {
      if (!compared(a, r, i)) continue;
      for (std::size_t c = 0; c < 3; ++c) {
        const double d = at(a, 3 * i + c) - at(r, 3 * i + c);
        diff2 += d * d;
        var += static_cast<double>(r.variance[3 * i + c]);
      }
    }
    if (std::isfinite(var) && var >= 0.0) {
      e.reference_noise = std::sqrt(var / ref2);
      if (ref2 > var) e.truth_rel_rmse = std::sqrt(std::max(0.0, diff2 - var) / (ref2 - var));
    }
  }
  e.rel_rmse = relative_rmse(a, r);
  e.max_rel = max_relative_error(a, r, options.max_rel_floor_eps);
  e.psnr_db = tonemapped_psnr_db(a, r, options.exposure);
  e.fit_scale = least_squares_scale(a, r);
  e.fit_rel_rmse = relative_rmse(a, r, e.fit_scale);
  e.fit_max_rel = max_relative_error(a, r, options.max_rel_floor_eps, e.fit_scale);
  e.fit_psnr_db = tonemapped_psnr_db(a, r, options.exposure, e.fit_scale);
  if (std::isnan(e.rel_rmse) || std::isnan(e.max_rel) || std::isnan(e.psnr_db) || std::isnan(e.fit_rel_rmse)) {
    // Finite inputs whose squares overflow double: say so rather than report NaN as a number.
    e.problem = "values too large to square in double precision";
  }
  return e;
}

}  // namespace gi
