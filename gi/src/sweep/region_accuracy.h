#pragma once
// The numbers of a frame-vs-truth comparison (gi/frame_truth.h) over a set of pixels: the
// luminance bias with the share of it the truth's noise could explain, and compare_rgb's
// errors against the truth's estimate and against the noise-free truth.
//   std::vector<std::uint8_t> in_region = ...;   // 1 for the pixels compared
//   gi::RegionAccuracy a = gi::measure_region("courtyard", frame, truth, truth_variance, in_region);

#include <gi/frame_truth.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/color.h"

namespace gi {

/// The accuracy of `frame` (RGBA, the renderer's) against `truth` (RGBA, the mean of two
/// halves) over the pixels whose `mask` is nonzero; `truth_variance` holds 3 values (R, G,
/// B) per pixel: the variance of the truth's estimate. Sizes must agree (GI_EXPECTS).
RegionAccuracy measure_region(const std::string& name, const engine::ImageRgbaF& frame, const engine::ImageRgbaF& truth,
                              std::span<const float> truth_variance, std::span<const std::uint8_t> mask);

}  // namespace gi
