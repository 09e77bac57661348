#pragma once
// The error and the correlation of a method's per-texel change against a truth that is known
// only through two independent noisy estimates (two path-traced references with different
// random streams), with the estimates' own noise removed (issue 37: "the per-texel error of
// the change, its noise removed").
//   gi::SplitTruthChangeScore s;
//   for (each texel, channel and moved pose) s.add(model_change, change_in_a, change_in_b);
//   double rel = std::sqrt(s.noise_removed_sse() / truth_sum_sq);
//
// Model: a = t + n_a, b = t + n_b with n_a, n_b independent, zero-mean, of the same variance
// v per sample, and independent of the method's change m. Then, per sample,
//   E[(a - b)^2] = 2 v,   mean c = (a + b) / 2 has variance v / 2 = E[(a - b)^2] / 4,
//   E[(m - c)^2] = (m - t)^2 + v / 2,
// so sum (m - c)^2 - sum (a - b)^2 / 4 is an unbiased estimate of sum (m - t)^2 (the light
// atlas's split truth removes the noise of the mean of two estimates the same way:
// mean_of_two_estimates in gi/src/sweep/atlas_split_truth.h). The correlation with the
// noise-free change: cov(m, c) estimates cov(m, t) without bias, var c overstates var t by
// the mean noise variance, so corr(m, t) = cov(m, c) / sqrt(var m (var c - v / 2))
// ("disattenuated" by the reliability of c, (var c - v / 2) / var c).
// The changes of one reference at two poses share their random stream, so the noise of a
// change is not the two poses' variances summed: it is measured from the two changes here.

#include <cstddef>

namespace gi {

/// Sums over samples (texel x channel x pose) of a method's change against two estimates of
/// the true change; the scores with the estimates' noise removed. Plain accumulator.
class SplitTruthChangeScore {
 public:
  /// One sample: the method's change `model`, the change in estimate a and in estimate b.
  void add(double model, double a, double b) {
    const double c = 0.5 * (a + b);
    n_ += 1.0;
    sm_ += model, sc_ += c, smm_ += model * model, scc_ += c * c, smc_ += model * c;
    sea_ += (model - a) * (model - a);
    sec_ += (model - c) * (model - c);
    sdd_ += (a - b) * (a - b);
  }
  /// Adds another accumulator's samples.
  void merge(const SplitTruthChangeScore& o) {
    n_ += o.n_, sm_ += o.sm_, sc_ += o.sc_, smm_ += o.smm_, scc_ += o.scc_, smc_ += o.smc_;
    sea_ += o.sea_, sec_ += o.sec_, sdd_ += o.sdd_;
  }

  /// Number of samples added.
  double samples() const { return n_; }
  /// sum (m - a)^2: the error against estimate a alone, its noise included (the old scores).
  double sse_against_a() const { return sea_; }
  /// sum of one estimate's noise variance, sum (a - b)^2 / 2: what sse_against_a() overstates.
  double noise_of_one() const { return 0.5 * sdd_; }
  /// sum (m - t)^2 estimated without bias: sum (m - c)^2 - sum (a - b)^2 / 4. May be
  /// negative when the method is within the noise of the truth.
  double noise_removed_sse() const { return sec_ - 0.25 * sdd_; }
  /// sum t^2 of the true change estimated without bias (changing nothing's noise_removed_sse).
  double truth_sum_sq() const { return scc_ - 0.25 * sdd_; }
  /// Pearson correlation of m with the mean change c (noise included); NaN when undefined.
  double correlation_raw() const;
  /// The correlation of m with the noise-free change t (see the header comment); NaN when
  /// undefined or when the noise explains all of c's variance.
  double correlation_noise_removed() const;
  /// The scale s minimising sum (s m - c)^2, sum m c / sum m m (unbiased for the one against
  /// t: the noise is independent of m). NaN when m is zero everywhere.
  double fit_scale() const;

 private:
  double n_ = 0.0, sm_ = 0.0, sc_ = 0.0, smm_ = 0.0, scc_ = 0.0, smc_ = 0.0;
  double sea_ = 0.0, sec_ = 0.0, sdd_ = 0.0;
};

/// The floor of a linear projection P (the leaves' blend of a per-texel field,
/// project_through_leaves) measured on a truth known only through two noisy estimates
/// a = t + n_a, b = t + n_b (independent noise of the same distribution; it may be correlated
/// across samples within one estimate). The floor's error is sum |P t - t|^2. Projecting one
/// estimate carries its noise: (P - I) a = (P - I) t + (P - I) n_a, and -n_a is the whole
/// noise. With the mean c = (a + b) / 2 and the half difference h = (a - b) / 2, whose noise
/// (n_a - n_b) / 2 has the covariance of c's (n_a + n_b) / 2 and which holds no truth,
///   E sum |(P - I) c|^2 = sum |(P - I) t|^2 + E sum |(P - I) h|^2,
/// so sum |P c - c|^2 - sum |P h - h|^2 estimates the floor without bias. The caller projects
/// c and h and adds the residuals sample by sample (channel by channel).
///   floor.add(pc[t][ch] - c[t][ch], ph[t][ch] - h[t][ch]);
class SplitTruthFloor {
 public:
  /// One sample: (P c - c) and (P h - h) there.
  void add(double residual_of_mean, double residual_of_half_difference) {
    n_ += 1.0;
    sc_ += residual_of_mean * residual_of_mean;
    sh_ += residual_of_half_difference * residual_of_half_difference;
  }
  void merge(const SplitTruthFloor& o) { n_ += o.n_, sc_ += o.sc_, sh_ += o.sh_; }
  double samples() const { return n_; }
  /// sum |P t - t|^2 estimated without bias; may be negative when the floor is within the noise.
  double noise_removed_sse() const { return sc_ - sh_; }
  /// sum |(P - I) h|^2: the noise the mean's floor carries (what noise_removed_sse() removed).
  double noise_sse() const { return sh_; }

 private:
  double n_ = 0.0, sc_ = 0.0, sh_ = 0.0;
};

}  // namespace gi
