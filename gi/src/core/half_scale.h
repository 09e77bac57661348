#pragma once
// The power-of-two scale under which a layer of non-negative values is stored as half floats
// (prm_panes.bin, dlm.bin, and the DLM's GPU upload): s = 2^(e - 15) where the layer's largest
// value is m x 2^e (m in [0.5, 1)), so the largest maps into [2^14, 2^15), the top of the half
// range, and every value keeps the half's 11 significant bits relative to it. Never below
// 2^-126, the smallest normal float: below it ldexp would give 0 or a denormal and the layer
// would not read back (a layer whose largest value is under ~1e-34 keeps fewer bits, which no
// physical radiance needs). 1 for an all-zero layer.
//   const float s = gi::half_layer_scale(max_value);  halves[j] = to_half(v[j] / s);

#include <algorithm>
#include <cmath>

namespace gi {

inline float half_layer_scale(float max_value) {
  if (!(max_value > 0.0f)) return 1.0f;
  int e = 0;
  std::frexp(max_value, &e);
  return std::ldexp(1.0f, std::max(e - 15, -126));
}

}  // namespace gi
