#version 450 core
// Push (Dachsbacher et al. 2007 §3.2 "Maintenance of the hierarchy"): the incident radiance
// gathered at inner nodes goes down the hierarchy, one level per dispatch from the root's
// children down (the CPU twin walks the same order):
//   L_in[n][bin] += L_in[parent(n)][bin]      for the nodes n of this level
// so that after the deepest level every leaf holds all the light arriving there.
// One invocation per (node of the level, bin).

#include "antiradiance_common.glsl"

layout(std430, binding = 0) readonly buffer Parents { int parents[]; };
layout(std430, binding = 1) readonly buffer ByLevel { int by_level[]; };
layout(std430, binding = 2) buffer Incident { float l_in[]; };

uniform uint u_first;  // this level's first entry in by_level

void main() {
  const uint item = item_index();
  if (item >= u_items) return;
  const uint n = uint(by_level[u_first + item / u_bins]);
  const uint bin = item % u_bins;
  const uint p = uint(parents[n]);
  const uint dst = (n * u_bins + bin) * 3u;
  const uint src = (p * u_bins + bin) * 3u;
  l_in[dst] = l_in[dst] + l_in[src];
  l_in[dst + 1u] = l_in[dst + 1u] + l_in[src + 1u];
  l_in[dst + 2u] = l_in[dst + 2u] + l_in[src + 2u];
}
