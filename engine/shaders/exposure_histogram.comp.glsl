#version 450 core
// Automatic exposure, pass 1 (docs/exposure.md): the histogram of log2 photometric luminance
// of the HDR frame. One work group per tile of (16 x PIXELS_PER_SIDE)^2 pixels counts into
// shared memory, then adds its non-empty bins to the global histogram (which the adapt pass
// reads and clears). Pixels darker than 2^METER_MIN_LOG2 cd/m^2 (or NaN) are not metered;
// brighter than the last bin count in it.
#include "exposure_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // 256 invocations: one per bin when merging
layout(binding = 0) uniform sampler2D u_hdr;
layout(location = 0) uniform ivec2 u_size;

shared uint s_count[METER_BINS];
shared uint s_sub_bin_sum[METER_BINS];

void meter(vec3 radiance) {
  const float l = photometric_luminance(radiance);
  if (!(l >= exp2(METER_MIN_LOG2))) return;
  const float top = float(METER_BINS) - 0.5 / float(SUB_BIN_STEPS);
  const float t = min((log2(l) - METER_MIN_LOG2) * float(BINS_PER_EV), top);
  const uint bin = uint(t);
  const uint step = min(uint((t - float(bin)) * float(SUB_BIN_STEPS)), uint(SUB_BIN_STEPS - 1));
  atomicAdd(s_count[bin], 1u);
  atomicAdd(s_sub_bin_sum[bin], step);
}

void main() {
  const uint i = gl_LocalInvocationIndex;
  s_count[i] = 0u;
  s_sub_bin_sum[i] = 0u;
  barrier();
  const ivec2 tile = ivec2(gl_WorkGroupID.xy) * (16 * PIXELS_PER_SIDE) + ivec2(gl_LocalInvocationID.xy);
  for (int y = 0; y < PIXELS_PER_SIDE; ++y)
    for (int x = 0; x < PIXELS_PER_SIDE; ++x) {
      const ivec2 p = tile + 16 * ivec2(x, y);
      if (p.x < u_size.x && p.y < u_size.y) meter(texelFetch(u_hdr, p, 0).rgb);
    }
  barrier();
  if (s_count[i] != 0u) {
    atomicAdd(hist_count[i], s_count[i]);
    atomicAdd(hist_sub_bin_sum[i], s_sub_bin_sum[i]);
  }
}
