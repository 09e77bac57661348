#version 450 core
// One bounce at every vertex of every instance (Iwasaki et al. eq. 12), per receiver term k'
// (1 for a diffuse receiver, K for a glossy one):
//   E_r,0(x_j)  = sum over r's live sources s of max(0, sum_c w_s,c Phi_sr,(0,c)(x_j))   per rgb
//   E_r,k'(x_j) = sum over r's live sources s of sum_c w_s,c Phi_sr,(k',c)(x_j)          (k' >= 1, signed)
// (c over the source's channels k x N + i) written to gathered[] and added to indirect[]
// ([k' x V + j] per instance). One invocation per vertex of every instance; its instance is
// found by binary search over the instances' vertex offsets. The twin of gather() in
// brf_runtime.cpp (same source order, same clamp per pair).

#include "brf_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Instances { BrfInstance instances[]; };
layout(std430, binding = 1) readonly buffer Models { BrfModel models[]; };
// Per live (source, receiver) pair: (source's first weight vec4, first Phi vec4 of the pair, C4 / 4, source).
layout(std430, binding = 2) readonly buffer LiveSources { uvec4 live_sources[]; };
layout(std430, binding = 3) readonly buffer Weights { vec4 weights[]; };          // rgb per channel, pads 0
layout(std430, binding = 4) readonly buffer Phi { vec4 phi[]; };                  // rows of C4 floats, pads 0
layout(std430, binding = 5) writeonly buffer Gathered { vec4 gathered[]; };
layout(std430, binding = 6) buffer Indirect { vec4 indirect[]; };

uniform uint u_instance_count;
uniform uint u_vertex_total;

const uint kMaxRows = 16u;  // 1 + kMaxGlossyTerms

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
  const uint rows = inst.terms;
  vec3 e[kMaxRows];
  for (uint r = 0u; r < rows; ++r) e[r] = vec3(0.0);
  for (uint l = 0u; l < inst.live_count; ++l) {
    const uvec4 src = live_sources[inst.live_first + l];
    const uint q4 = src.z;
    for (uint r = 0u; r < rows; ++r) {
      const uint at = src.y + (j * rows + r) * q4;
      vec3 pair = vec3(0.0);
      for (uint q = 0u; q < q4; ++q) {
        const vec4 p = phi[at + q];
        const uint w = src.x + 4u * q;
        pair += p.x * weights[w].xyz + p.y * weights[w + 1u].xyz + p.z * weights[w + 2u].xyz + p.w * weights[w + 3u].xyz;
      }
      e[r] += r == 0u ? max(pair, vec3(0.0)) : pair;  // SH ringing must not make the irradiance negative
    }
  }
  for (uint r = 0u; r < rows; ++r) {
    const uint at = inst.value_offset + r * inst.vertex_count + j;
    gathered[at] = vec4(e[r], 0.0);
    indirect[at] += vec4(e[r], 0.0);
  }
}
