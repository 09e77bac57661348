#version 450 core
// Pull (Dachsbacher et al. 2007 §3.2, §4.2): intensities add up the hierarchy, one level
// per dispatch from the deepest inner nodes up (the CPU twin walks the same order):
//   I_ex[n][bin] = sum over n's children c (in child order) of I_ex[c][bin]
// One invocation per (node of the level, bin); leaves of the level are skipped.

#include "antiradiance_common.glsl"

layout(std430, binding = 0) readonly buffer Nodes { ivec2 child_range[]; };  // first child, child count
layout(std430, binding = 1) readonly buffer Children { int children[]; };
layout(std430, binding = 2) readonly buffer ByLevel { int by_level[]; };
layout(std430, binding = 3) buffer Exitant { float i_ex[]; };

uniform uint u_first;  // this level's first entry in by_level

void main() {
  const uint item = item_index();
  if (item >= u_items) return;
  const uint n = uint(by_level[u_first + item / u_bins]);
  const uint bin = item % u_bins;
  const ivec2 range = child_range[n];
  if (range.y == 0) return;
  vec3 sum = vec3(0.0);
  for (int c = 0; c < range.y; ++c) {
    const uint src = (uint(children[range.x + c]) * u_bins + bin) * 3u;
    sum += vec3(i_ex[src], i_ex[src + 1u], i_ex[src + 2u]);
  }
  const uint dst = (n * u_bins + bin) * 3u;
  i_ex[dst] = sum.x;
  i_ex[dst + 1u] = sum.y;
  i_ex[dst + 2u] = sum.z;
}
