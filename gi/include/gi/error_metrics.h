#pragma once
// Accuracy of a GI method's output against a reference: the project's error metrics.
//   gi::ErrorReport e = gi::compare_rgb(method_output, reference);
//   if (e.ok()) std::printf("rel RMSE %.3f, max %.3f, PSNR %.1f dB\n", e.rel_rmse, e.max_rel, e.psnr_db);
//
// Definitions (a = approximation, r = reference, i runs over the compared elements, c over
// R, G, B; an element is compared when it is valid in BOTH fields' masks):
//   relative RMSE   = sqrt( sum_i sum_c (a_ic - r_ic)^2 / sum_i sum_c r_ic^2 )
//                     -- the headline metric: channels are summed, not averaged per channel,
//                        so it is the relative L2 error of the whole RGB signal.
//   max relative    = max_i |a_i - r_i| / max(|r_i|, floor_eps * mean_i |r_i|)
//                     with |.| the Euclidean norm of the RGB triple; the floor (default
//                     floor_eps = 0.01, i.e. 1% of the mean reference magnitude) keeps
//                     near-black reference elements from dividing by ~0.
//   PSNR            = 10 log10(1 / MSE) dB, MSE over i and c of (T(a_ic) - T(r_ic))^2 where
//                     T = display_tonemap (exposure, ACES Narkowicz clamped, sRGB encode), so
//                     values are in [0, 1] = the 8-bit range 0..255 (not quantized);
//                     +infinity when the tonemapped images are identical.
//   scale fit       = s minimising sum |s a - r|^2, i.e. s = sum a.r / sum a.a (s = 1 when
//                     a is zero everywhere); the fit_* metrics are the above for s a.
//   reference noise = sqrt( sum_i sum_c v_ic / sum_i sum_c r_ic^2 ), v = the reference's
//                     sampling variance (RgbField::variance): its own relative RMSE from
//                     the truth it estimates.
//   truth rel RMSE  = sqrt( max(0, sum (a - r)^2 - sum v) / (sum r^2 - sum v) ): the
//                     relative RMSE against the noise-free truth t. With r = t + noise
//                     independent of a, E[(a - r)^2] = (a - t)^2 + v and E[r^2] = t^2 + v,
//                     so both sums are unbiased; it removes the floor a noisy reference puts
//                     under every method's rel RMSE. NaN without a variance.
// Problems make a report not ok() and its metrics NaN -- never silently averaged:
// non-finite (NaN/Inf) values among compared elements (counted per side), no compared
// elements (empty masks), or a reference that is zero on every compared element (relative
// error undefined). Different layouts or inconsistent vector sizes are programmer errors
// (GI_EXPECTS): whoever produces the fields owns their shape (the sweep harness checks a
// method's output before comparing and reports a mismatch as that run's error).

#include <gi/rgb_field.h>

#include <cstddef>
#include <string>

namespace gi {

/// Knobs of the metrics themselves.
struct MetricOptions {
  double max_rel_floor_eps = 1e-2;  ///< Floor of max-relative denominators, as a fraction of mean |r|.
  double exposure = 1.0;            ///< Exposure applied before the tonemap, for PSNR.
};

/// Every metric of one comparison. Metrics are NaN when !ok().
struct ErrorReport {
  std::size_t elements_compared = 0;    ///< Elements valid in both masks.
  std::size_t nonfinite_approx = 0;     ///< NaN/Inf channel values of the approximation among them.
  std::size_t nonfinite_reference = 0;  ///< NaN/Inf channel values of the reference among them.
  std::string problem;                  ///< Empty when the metrics are meaningful; else why not.

  double rel_rmse = 0.0;
  double max_rel = 0.0;
  double psnr_db = 0.0;  ///< +inf for identical tonemapped images.
  double fit_scale = 1.0;
  double fit_rel_rmse = 0.0;
  double fit_max_rel = 0.0;
  double fit_psnr_db = 0.0;
  double reference_noise = 0.0;  ///< NaN when the reference carries no variance.
  double truth_rel_rmse = 0.0;   ///< NaN when the reference carries no variance.

  bool ok() const { return problem.empty(); }
};

/// All metrics of `approx` against `reference` (see the definitions above).
ErrorReport compare_rgb(const RgbField& approx, const RgbField& reference, const MetricOptions& options = {});

// The single metrics. `scale` multiplies the approximation. They return NaN when a compared
// value is non-finite or the metric is undefined (no compared element, zero reference);
// compare_rgb says which. Preconditions as for compare_rgb.

/// Relative RMSE of (scale * approx) against reference.
double relative_rmse(const RgbField& approx, const RgbField& reference, double scale = 1.0);
/// Maximum relative error of (scale * approx), denominators floored at floor_eps * mean |r|.
double max_relative_error(const RgbField& approx, const RgbField& reference, double floor_eps = 1e-2,
                          double scale = 1.0);
/// PSNR in dB of the tonemapped images (peak 1.0); +inf when identical.
double tonemapped_psnr_db(const RgbField& approx, const RgbField& reference, double exposure = 1.0, double scale = 1.0);
/// The least-squares s minimising sum |s a - r|^2 (1 when a is zero on every compared element).
double least_squares_scale(const RgbField& approx, const RgbField& reference);

}  // namespace gi
