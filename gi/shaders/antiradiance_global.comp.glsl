#version 450 core
// Global pass (operator U, Dachsbacher et al. 2007 eq. 16-17): for every node r,
//   L_in[r][bin] = sum over r's links (sender s, bin, F) of F * I_ex[s][bin]
// links sorted by receiver (offsets[r] .. offsets[r+1]) and summed in that order, as the
// CPU twin (CpuAntiradiancePasses::global) does. One invocation per node writes its row.

#include "antiradiance_common.glsl"

struct Link {
  uint sender;
  uint bin;
  float form_factor;
  uint pad;
};

layout(std430, binding = 0) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 1) readonly buffer Links { Link links[]; };
layout(std430, binding = 2) readonly buffer Exitant { float i_ex[]; };
layout(std430, binding = 3) buffer Incident { float l_in[]; };

void main() {
  const uint r = item_index();
  if (r >= u_items) return;
  const uint row = r * u_bins * 3u;
  for (uint k = 0u; k < u_bins * 3u; ++k) l_in[row + k] = 0.0;
  // Accumulate in registers per bin would need m registers; links of one receiver are
  // sorted by sender then bin, so write through memory in link order (same order as the CPU).
  for (uint k = offsets[r]; k < offsets[r + 1u]; ++k) {
    const Link l = links[k];
    const uint dst = row + l.bin * 3u;
    const uint src = (l.sender * u_bins + l.bin) * 3u;
    l_in[dst + 0u] = l_in[dst + 0u] + l.form_factor * i_ex[src + 0u];
    l_in[dst + 1u] = l_in[dst + 1u] + l.form_factor * i_ex[src + 1u];
    l_in[dst + 2u] = l_in[dst + 2u] + l.form_factor * i_ex[src + 2u];
  }
}
