#version 450 core
// Global pass (operator U, Dachsbacher et al. 2007 eq. 16-17): for every node r and bin b,
//   L_in[r][b] = sum over r's links (sender s, bin b, F) of F * I_ex[s][b]
// Links are sorted by (receiver, bin, sender), so each (r, b) is one contiguous run; one
// invocation sums one run in link order (as CpuAntiradiancePasses::global does) and writes
// its entry once. Entries without links were cleared before the dispatch.

#include "antiradiance_common.glsl"

// A link's bin is its run's (run.z = receiver * bins + bin), so a link is 8 bytes.
struct Link {
  uint sender;
  float form_factor;
};

layout(std430, binding = 0) readonly buffer Runs { uvec4 runs[]; };  // first link, count, destination entry, 0
layout(std430, binding = 1) readonly buffer Links { Link links[]; };
layout(std430, binding = 2) readonly buffer Exitant { float i_ex[]; };
layout(std430, binding = 3) writeonly buffer Incident { float l_in[]; };

void main() {
  const uint i = item_index();
  if (i >= u_items) return;
  const uvec4 run = runs[i];
  const uint bin = run.z % u_bins;
  vec3 sum = vec3(0.0);
  for (uint k = run.x; k < run.x + run.y; ++k) {
    const Link l = links[k];
    const uint src = (l.sender * u_bins + bin) * 3u;
    sum += l.form_factor * vec3(i_ex[src], i_ex[src + 1u], i_ex[src + 2u]);
  }
  const uint dst = run.z * 3u;
  l_in[dst] = sum.x;
  l_in[dst + 1u] = sum.y;
  l_in[dst + 2u] = sum.z;
}
