#version 450 core
// Pull (Dachsbacher et al. 2007 §3.2, §4.2): an inner node's exitant intensity is the sum of
// its leaves' (intensities add up the hierarchy), summed in leaf order as the CPU twin does:
//   I_ex[node][bin] = sum over leaves i in [leaf_begin, leaf_end) of I_ex[leaves[i]][bin]
// One invocation per (inner node, bin); the inner nodes are listed in `inner`.

#include "antiradiance_common.glsl"

layout(std430, binding = 0) readonly buffer Inner { ivec4 inner[]; };  // node, leaf_begin, leaf_end, 0
layout(std430, binding = 1) readonly buffer Leaves { int leaves[]; };
layout(std430, binding = 2) buffer Exitant { float i_ex[]; };

void main() {
  const uint item = item_index();
  if (item >= u_items) return;
  const ivec4 node = inner[item / u_bins];
  const uint bin = item % u_bins;
  vec3 sum = vec3(0.0);
  for (int i = node.y; i < node.z; ++i) {
    const uint src = (uint(leaves[i]) * u_bins + bin) * 3u;
    sum += vec3(i_ex[src], i_ex[src + 1u], i_ex[src + 2u]);
  }
  const uint dst = (uint(node.x) * u_bins + bin) * 3u;
  i_ex[dst] = sum.x;
  i_ex[dst + 1u] = sum.y;
  i_ex[dst + 2u] = sum.z;
}
