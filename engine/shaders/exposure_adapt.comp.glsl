#version 450 core
// Automatic exposure, pass 2 (docs/exposure.md, engine/exposure.h): one invocation reads the
// histogram, takes the mean log2 luminance of the pixels ranked between the two percentiles
// (the bins at the edges count in part), turns it into a target EV100 (reflected-light meter,
// clamp, compensation), moves the adapted EV100 toward it at the rate for the direction of
// the change over this frame's time step (or snaps to it), writes the exposure the tonemap
// reads, and clears the histogram for the next frame.
#include "exposure_common.glsl"

layout(local_size_x = 1) in;
uniform float u_dt_s;
uniform int u_snap;
uniform vec2 u_percentiles;  // low, high (fractions of the metered pixels)
uniform vec2 u_ev100_range;  // min, max of the metered EV100
uniform float u_compensation_ev;
uniform vec2 u_rates_per_s;  // scene got brighter, scene got darker

void main() {
  uint total = 0u;
  for (uint i = 0u; i < uint(METER_BINS); ++i) total += hist_count[i];
  const float lo = u_percentiles.x * float(total);
  const float hi = u_percentiles.y * float(total);
  float kept = 0.0;
  float sum_log2 = 0.0;
  uint below = 0u;
  for (uint i = 0u; i < uint(METER_BINS); ++i) {
    const uint c = hist_count[i];
    if (c == 0u) continue;
    const float a = max(lo, float(below));
    const float b = min(hi, float(below + c));
    if (b > a) {
      kept += b - a;
      sum_log2 += (b - a) * bin_mean_log2(i, c, hist_sub_bin_sum[i]);
    }
    below += c;
    hist_count[i] = 0u;
    hist_sub_bin_sum[i] = 0u;
  }
  const float mean_log2 = kept > 0.0 ? sum_log2 / kept : METER_MIN_LOG2;
  const float metered_ev = kept > 0.0 ? mean_log2 + METER_EV_OFFSET : u_ev100_range.x;
  const float target = clamp(metered_ev, u_ev100_range.x, u_ev100_range.y) - u_compensation_ev;
  float ev = target;
  if (u_snap == 0) {
    const float rate = target > state_ev100 ? u_rates_per_s.x : u_rates_per_s.y;
    ev = target + (state_ev100 - target) * exp(-rate * u_dt_s);
  }
  state_ev100 = ev;
  state_exposure = LUMENS_PER_WATT / (SATURATION_SCALE * exp2(ev));
  state_target_ev100 = target;
  state_mean_log2 = mean_log2;
  state_metered_pixels = total;
}
