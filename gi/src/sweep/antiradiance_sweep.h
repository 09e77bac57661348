#pragma once
// Antiradiance (docs/antiradiance.md) in the sweep harness: knobs element size x bins x
// iterations (x scheme, oracle), judged by what it adds to the renderer's atlas when the
// scene's deforming node (the corridor's door) swings away from its baked pose.
//
// The quantity: the region outputs the CHANGE of indirect irradiance since the baked pose,
// blended onto atlas texels as the runtime does (antiradiance_texel_blend.h). A run bakes at
// the authored pose, swings the first deforming instance about its local Y axis by -50,
// -25 and +50 degrees (the corridor's door, authored at 50: shut 0, 25, wide 100), and at
// every compared texel outputs E_ref(baked) + delta_antiradiance(angle), i.e. a perfect bake
// of the authored pose plus the method's change. The reference (kind
// "atlas_indirect_irradiance_door") is the path tracer's indirect irradiance at the same
// texels with the door at each angle, same random streams per texel for every pose (common
// random numbers: paths the door does not touch cancel in the change). So the harness's
// relative RMSE is RMS(change error) / RMS(true indirect level) over the compared texels
// and angles: 0 for a perfect change, RMS(true change)/RMS(level) ("extra:nothing_rel_rmse")
// for a method that changes nothing. Per swing, "extra:change_nrmse_swing_<m50|m25|p50>" is
// RMS(change error) / mean(baked indirect level) over the compared texels (RGB channels
// pooled), "extra:nothing_nrmse_swing_*" the same measure of changing nothing,
// "extra:true_mean_change_swing_*" and "extra:mean_change_error_swing_*" the mean true change
// and the error of the method's mean change over the compared texels (/ level), and
// "extra:change_correlation" / "extra:change_fit_scale" how the per-texel changes agree.
//
// Field layout (reference and output): the atlas at `density` texels/m stacked vertically,
// block 0 the baked pose (the reference's; the output masks it out), block k the k-th
// angle. Compared texels: static, non-deforming instances' texels within `radius` metres
// of the door's swept bounds.

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "atlas_indirect_irradiance_door" reference provider and the "antiradiance" method.
void register_antiradiance_sweep(SweepRegistry& registry);

}  // namespace gi
