#include "sweep/atlas_split_truth.h"

#include <engine/check.h>
#include <gi/error_metrics.h>

#include <cstddef>
#include <limits>

namespace gi {
namespace {

// Rows [first_row, first_row + rows) of `f` as a field of their own.
RgbField rows_of(const RgbField& f, int first_row, int rows) {
  RgbField out;
  out.width = f.width;
  out.height = rows;
  const std::size_t begin = static_cast<std::size_t>(first_row) * static_cast<std::size_t>(f.width);
  const std::size_t n = out.count();
  out.rgb.assign(f.rgb.begin() + static_cast<std::ptrdiff_t>(3 * begin),
                 f.rgb.begin() + static_cast<std::ptrdiff_t>(3 * (begin + n)));
  if (!f.valid.empty())
    out.valid.assign(f.valid.begin() + static_cast<std::ptrdiff_t>(begin),
                     f.valid.begin() + static_cast<std::ptrdiff_t>(begin + n));
  if (!f.variance.empty())
    out.variance.assign(f.variance.begin() + static_cast<std::ptrdiff_t>(3 * begin),
                        f.variance.begin() + static_cast<std::ptrdiff_t>(3 * (begin + n)));
  return out;
}

template <class T>
std::vector<T> concat(const std::vector<T>& a, const std::vector<T>& b) {
  std::vector<T> out = a;
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

double channel_sum(const RgbField& f, std::size_t i) {
  return static_cast<double>(f.rgb[3 * i]) + static_cast<double>(f.rgb[3 * i + 1]) +
         static_cast<double>(f.rgb[3 * i + 2]);
}

}  // namespace

RgbField stack_split_truth(const RgbField& indirect, const RgbField& total) {
  GI_EXPECTS(indirect.consistent() && total.consistent() && indirect.same_layout(total),
             "stack_split_truth: both halves must be consistent fields of one layout");
  GI_EXPECTS(indirect.variance.empty() == total.variance.empty() && indirect.valid.empty() == total.valid.empty(),
             "stack_split_truth: both halves must carry a variance and a mask, or neither");
  RgbField out;
  out.width = indirect.width;
  out.height = 2 * indirect.height;
  out.rgb = concat(indirect.rgb, total.rgb);
  out.valid = concat(indirect.valid, total.valid);
  out.variance = concat(indirect.variance, total.variance);
  return out;
}

AtlasSplitTruth unstack_split_truth(const RgbField& stacked) {
  GI_EXPECTS(stacked.consistent() && stacked.height % 2 == 0,
             "unstack_split_truth: a consistent field of even height (stack_split_truth's)");
  const int h = stacked.height / 2;
  return {.indirect = rows_of(stacked, 0, h), .total = rows_of(stacked, h, h)};
}

RgbField mean_of_two_estimates(const RgbField& a, const RgbField& b) {
  GI_EXPECTS(a.consistent() && b.consistent() && a.same_layout(b),
             "mean_of_two_estimates: two consistent fields of one layout");
  RgbField out;
  out.width = a.width;
  out.height = a.height;
  out.rgb.resize(a.rgb.size());
  out.variance.resize(a.rgb.size());
  const bool own_variances = !a.variance.empty() && !b.variance.empty();
  for (std::size_t k = 0; k < a.rgb.size(); ++k) {
    out.rgb[k] = 0.5f * (a.rgb[k] + b.rgb[k]);
    const float d = a.rgb[k] - b.rgb[k];
    out.variance[k] = own_variances ? 0.25f * (a.variance[k] + b.variance[k]) : 0.25f * d * d;
  }
  if (!a.valid.empty() || !b.valid.empty()) {
    out.valid.resize(a.count());
    for (std::size_t i = 0; i < a.count(); ++i) out.valid[i] = a.is_valid(i) && b.is_valid(i) ? 1 : 0;
  }
  return out;
}

std::vector<std::uint8_t> indirect_dominated_mask(const AtlasSplitTruth& truth, double share) {
  GI_EXPECTS(truth.indirect.consistent() && truth.total.consistent() && truth.indirect.same_layout(truth.total),
             "indirect_dominated_mask: the halves must be consistent fields of one layout");
  std::vector<std::uint8_t> mask(truth.total.count(), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) {
    const double total = channel_sum(truth.total, i);
    mask[i] = truth.total.is_valid(i) && truth.indirect.is_valid(i) &&
                      is_indirect_dominated(channel_sum(truth.indirect, i), total, share)
                  ? 1
                  : 0;
  }
  return mask;
}

std::vector<std::pair<std::string, double>> split_truth_extras(const RgbField& total, const AtlasSplitTruth& truth) {
  GI_EXPECTS(total.consistent() && total.same_layout(truth.total),
             "split_truth_extras: the method's total must have the truth's layout");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ErrorReport whole = compare_rgb(total, truth.total);
  RgbField dominated = truth.total;
  dominated.valid = indirect_dominated_mask(truth);
  std::size_t compared = 0, selected = 0;
  double sum_total = 0.0, sum_truth = 0.0;
  for (std::size_t i = 0; i < total.count(); ++i) {
    if (!total.is_valid(i) || !truth.total.is_valid(i)) continue;
    ++compared;
    selected += dominated.valid[i];
    sum_total += channel_sum(total, i);
    sum_truth += channel_sum(truth.total, i);
  }
  const ErrorReport part = compare_rgb(total, dominated);
  return {{"indirect_dominated", part.ok() ? part.truth_rel_rmse : nan},
          {"indirect_dominated_share", compared ? static_cast<double>(selected) / static_cast<double>(compared) : nan},
          {"whole", whole.ok() ? whole.truth_rel_rmse : nan},
          {"whole_bias", sum_truth > 0.0 ? sum_total / sum_truth - 1.0 : nan}};
}

}  // namespace gi
