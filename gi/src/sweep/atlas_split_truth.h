#pragma once
// The light atlas's truth split into indirect and total irradiance, and the two measures of
// issue 35 read against it: the error on the texels whose light arrives mostly by a bounce
// (truth indirect >= 80% of the truth total) and the error of the whole lightmap (direct +
// sky + indirect, what `gi-bake --include-direct` puts in the atlas). Both compare totals,
// so they do not depend on where a tool draws the line between direct and indirect light
// (under a sky the atlas and the path tracer draw it differently); the split only picks the
// texels of the first measure, by the path tracer's definition.
//   gi::RgbField stacked = gi::stack_split_truth(indirect_truth, total_truth);
//   auto extras = gi::split_truth_extras(atlas_total, gi::unstack_split_truth(stacked));

#include <gi/rgb_field.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace gi {

/// The truth's two halves, each width x height with its mask and its sampling variance.
struct AtlasSplitTruth {
  RgbField indirect;
  RgbField total;
};

/// Share of the truth's total a texel's truth indirect must reach to count as indirect-dominated.
inline constexpr double kIndirectDominatedShare = 0.8;

/// Whether a texel whose truth indirect and total (each summed over R, G, B) are given counts
/// as indirect-dominated: a total > 0 of which the indirect is at least `share`. A texel the
/// truth leaves dark (a closed pocket) is neither direct- nor indirect-dominated.
inline bool is_indirect_dominated(double indirect, double total, double share = kIndirectDominatedShare) {
  return total > 0.0 && indirect >= share * total;
}

/// One field of width x 2 height: rows [0, h) `indirect`, rows [h, 2h) `total`, masks and
/// variances stacked the same way (a reference is one RgbField). Precondition: same layout,
/// consistent, both with a variance or both without, both masked or both not.
RgbField stack_split_truth(const RgbField& indirect, const RgbField& total);
/// The inverse of stack_split_truth. Precondition: consistent, an even height.
AtlasSplitTruth unstack_split_truth(const RgbField& stacked);

/// The mean of two independent estimates of the same quantity (two path-traced truths with
/// different seeds), valid where both are. Its variance (the noise compare_rgb removes):
/// (var a + var b) / 4 when both carry their own, else the unbiased (a - b)^2 / 4 per
/// element and channel (E[(a - b)^2] = var a + var b). Precondition: same layout, consistent.
RgbField mean_of_two_estimates(const RgbField& a, const RgbField& b);

/// 1 for the valid texels of `truth` whose indirect (summed over R, G, B) is at least
/// `share` of their total (> 0), else 0.
std::vector<std::uint8_t> indirect_dominated_mask(const AtlasSplitTruth& truth, double share = kIndirectDominatedShare);

/// The measures of `total` (the method's whole lightmap, same layout as the truth's halves)
/// as (name, value) sweep extras:
///   indirect_dominated        truth_rel_rmse (error_metrics.h) of the total over the
///                             indirect-dominated texels (NaN when there are none);
///   indirect_dominated_share  their fraction of the compared texels;
///   whole                     truth_rel_rmse of the total over every compared texel;
///   whole_bias                sum total / sum truth total - 1 over them (+: too bright).
std::vector<std::pair<std::string, double>> split_truth_extras(const RgbField& total, const AtlasSplitTruth& truth);

}  // namespace gi
