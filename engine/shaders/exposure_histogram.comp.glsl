#version 450 core
// Automatic exposure, pass 1 (docs/exposure.md): the histogram of log2 photometric luminance
// of the HDR frame, metered on every METER_STRIDE-th pixel of every METER_STRIDE-th row from
// the bottom-left corner (GL's pixel (0, 0)). One work group per tile of
// (16 x PIXELS_PER_SIDE x METER_STRIDE)^2 pixels counts into shared memory, then adds its
// non-empty bins to the global histogram (which the adapt pass reads and clears). Pixels
// darker than 2^METER_MIN_LOG2 cd/m^2 (or NaN) are not metered; brighter than the last bin
// count in it.
// On llvmpipe the shared atomics cost, so each invocation meters a block of PIXELS_PER_SIDE^2
// neighbouring metered pixels and adds a run of pixels falling in the same bin at once, and a
// bin's count and sum of sub-bin steps share one word (count << 16 | sum: a tile meters at
// most 4096 pixels, so the count fits 13 bits and the sum 4096 x 15 < 2^16).
#include "exposure_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // 256 invocations: one per bin when merging
layout(binding = 0) uniform sampler2D u_hdr;
uniform ivec2 u_size;

shared uint s_bins[METER_BINS];  // count << 16 | sum of sub-bin steps

void main() {
  const uint i = gl_LocalInvocationIndex;
  s_bins[i] = 0u;
  barrier();
  const ivec2 block =
      (ivec2(gl_WorkGroupID.xy) * 16 + ivec2(gl_LocalInvocationID.xy)) * (PIXELS_PER_SIDE * METER_STRIDE);
  const float top = float(METER_BINS) - 0.5 / float(SUB_BIN_STEPS);
  uint run_bin = 0u;
  uint run = 0u;  // pixels of the current run, packed as a bin word
  for (int y = 0; y < PIXELS_PER_SIDE; ++y)
    for (int x = 0; x < PIXELS_PER_SIDE; ++x) {
      const ivec2 p = block + METER_STRIDE * ivec2(x, y);
      if (p.x >= u_size.x || p.y >= u_size.y) continue;
      const float l = photometric_luminance(texelFetch(u_hdr, p, 0).rgb);
      if (!(l >= exp2(METER_MIN_LOG2))) continue;
      const float t = min((log2(l) - METER_MIN_LOG2) * float(BINS_PER_EV), top);
      const uint bin = uint(t);
      const uint step = min(uint((t - float(bin)) * float(SUB_BIN_STEPS)), uint(SUB_BIN_STEPS - 1));
      if (run != 0u && bin != run_bin) {
        atomicAdd(s_bins[run_bin], run);
        run = 0u;
      }
      run_bin = bin;
      run += (1u << 16) | step;
    }
  if (run != 0u) atomicAdd(s_bins[run_bin], run);
  barrier();
  const uint word = s_bins[i];
  if (word != 0u) {
    atomicAdd(hist_count[i], word >> 16);
    atomicAdd(hist_sub_bin_sum[i], word & 0xffffu);
  }
}
