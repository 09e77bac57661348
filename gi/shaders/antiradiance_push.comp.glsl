#version 450 core
// Push (Dachsbacher et al. 2007 §3.2 "Maintenance of the hierarchy"): the incident radiance
// gathered at inner nodes goes down to the leaves,
//   L_leaf[leaf][bin] = L_in[leaf's node][bin] + L_in[parent][bin] + ... + L_in[root][bin]
// (leaf first, then up, as the CPU twin sums). One invocation per (leaf, bin).

#include "antiradiance_common.glsl"

layout(std430, binding = 0) readonly buffer Parents { int parents[]; };
layout(std430, binding = 1) readonly buffer Leaves { int leaves[]; };
layout(std430, binding = 2) readonly buffer Incident { float l_in[]; };
layout(std430, binding = 3) writeonly buffer IncidentLeaf { float l_leaf[]; };

void main() {
  const uint item = item_index();
  if (item >= u_items) return;
  const uint leaf = item / u_bins;
  const uint bin = item % u_bins;
  vec3 sum = vec3(0.0);
  for (int a = leaves[leaf]; a >= 0; a = parents[a]) {
    const uint src = (uint(a) * u_bins + bin) * 3u;
    sum += vec3(l_in[src], l_in[src + 1u], l_in[src + 2u]);
  }
  const uint dst = item * 3u;
  l_leaf[dst] = sum.x;
  l_leaf[dst + 1u] = sum.y;
  l_leaf[dst + 2u] = sum.z;
}
