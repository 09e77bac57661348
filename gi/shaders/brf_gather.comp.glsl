#version 450 core
// One bounce at every vertex of every instance (Iwasaki et al. eq. 12):
//   E_r(x_j) = sum over r's live sources s of max(0, sum_i w_s,i Phi_sr,i(x_j))   per channel
// written to gathered[] and added to indirect[]. One invocation per global vertex; its
// instance is found by binary search over the instances' vertex offsets. The twin of
// gather() in brf_runtime.cpp (same source order, same clamp per pair).

#include "brf_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Instances { BrfInstance instances[]; };
layout(std430, binding = 1) readonly buffer Models { BrfModel models[]; };
// Per live (source, receiver) pair: (source's first weight vec4, first Phi vec4 of the pair, N4 / 4, source).
layout(std430, binding = 2) readonly buffer LiveSources { uvec4 live_sources[]; };
layout(std430, binding = 3) readonly buffer Weights { vec4 weights[]; };          // rgb per basis function, pads 0
layout(std430, binding = 4) readonly buffer Phi { vec4 phi[]; };                  // rows of N4 floats, pads 0
layout(std430, binding = 5) writeonly buffer Gathered { vec4 gathered[]; };
layout(std430, binding = 6) buffer Indirect { vec4 indirect[]; };

uniform uint u_instance_count;
uniform uint u_vertex_total;

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint gv = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (gv >= u_vertex_total) return;
  // The last instance whose first vertex is <= gv.
  uint lo = 0u, hi = u_instance_count - 1u;
  while (lo < hi) {
    const uint mid = (lo + hi + 1u) / 2u;
    if (instances[mid].vertex_offset <= gv) lo = mid; else hi = mid - 1u;
  }
  const BrfInstance inst = instances[lo];
  const uint j = gv - inst.vertex_offset;
  vec3 e = vec3(0.0);
  for (uint l = 0u; l < inst.live_count; ++l) {
    const uvec4 src = live_sources[inst.live_first + l];
    const uint q4 = src.z;
    const uint at = src.y + j * q4;
    vec3 pair = vec3(0.0);
    for (uint q = 0u; q < q4; ++q) {
      const vec4 p = phi[at + q];
      const uint w = src.x + 4u * q;
      pair += p.x * weights[w].xyz + p.y * weights[w + 1u].xyz + p.z * weights[w + 2u].xyz + p.w * weights[w + 3u].xyz;
    }
    e += max(pair, vec3(0.0));  // SH ringing must not make light negative
  }
  gathered[gv] = vec4(e, 0.0);
  indirect[gv] += vec4(e, 0.0);
}
