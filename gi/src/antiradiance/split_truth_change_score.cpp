#include "antiradiance/split_truth_change_score.h"

#include <cmath>
#include <limits>

namespace gi {

double SplitTruthChangeScore::correlation_raw() const {
  if (n_ < 2.0) return std::numeric_limits<double>::quiet_NaN();
  const double cov = smc_ - sm_ * sc_ / n_, var_m = smm_ - sm_ * sm_ / n_, var_c = scc_ - sc_ * sc_ / n_;
  if (!(var_m > 0.0) || !(var_c > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return cov / std::sqrt(var_m * var_c);
}

double SplitTruthChangeScore::correlation_noise_removed() const {
  if (n_ < 2.0) return std::numeric_limits<double>::quiet_NaN();
  // The noise of c is zero-mean, so it adds sum (a - b)^2 / 4 to c's sum of squared
  // deviations from the mean (up to a 1/n of it, the noise of c's mean, kept for exactness).
  const double noise = 0.25 * sdd_ * (1.0 - 1.0 / n_);
  const double cov = smc_ - sm_ * sc_ / n_, var_m = smm_ - sm_ * sm_ / n_, var_t = scc_ - sc_ * sc_ / n_ - noise;
  if (!(var_m > 0.0) || !(var_t > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return cov / std::sqrt(var_m * var_t);
}

double SplitTruthChangeScore::fit_scale() const {
  return smm_ > 0.0 ? smc_ / smm_ : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace gi
