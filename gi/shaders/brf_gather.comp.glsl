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

// The read-only inputs are buffer textures: llvmpipe (Mesa 22) runs each SSBO load as a loop
// over the SIMD lanes, a texel fetch is one gather.
// Unit 0: the instance table, 4 uvec4 per BrfInstance (texel 2: model, vertex_offset,
// vertex_count, weight_offset; 3: live_first, live_count, value_offset, terms).
layout(binding = 0) uniform usamplerBuffer u_instances;
// Unit 1: per live (source, receiver) pair: (source's first weight vec4, first Phi vec4 of the pair, C4 / 4, source).
layout(binding = 1) uniform usamplerBuffer u_live_sources;
layout(binding = 2) uniform samplerBuffer u_weights;  // rgb per channel, pads 0
layout(binding = 3) uniform samplerBuffer u_phi;      // rows of C4 floats, pads 0
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
    if (texelFetch(u_instances, int(4u * mid + 2u)).y <= gv) lo = mid; else hi = mid - 1u;
  }
  const uvec4 ia = texelFetch(u_instances, int(4u * lo + 2u)), ib = texelFetch(u_instances, int(4u * lo + 3u));
  const uint vertex_offset = ia.y, vertex_count = ia.z, live_first = ib.x, live_count = ib.y, value_offset = ib.z;
  const uint j = gv - vertex_offset;
  const uint rows = ib.w;
  vec3 e[kMaxRows];
  for (uint r = 0u; r < rows; ++r) e[r] = vec3(0.0);
  for (uint l = 0u; l < live_count; ++l) {
    const uvec4 src = texelFetch(u_live_sources, int(live_first + l));
    const uint q4 = src.z;
    for (uint r = 0u; r < rows; ++r) {
      const uint at = src.y + (j * rows + r) * q4;
      vec3 pair = vec3(0.0);
      for (uint q = 0u; q < q4; ++q) {
        const vec4 p = texelFetch(u_phi, int(at + q));
        const int w = int(src.x + 4u * q);
        pair += p.x * texelFetch(u_weights, w).xyz + p.y * texelFetch(u_weights, w + 1).xyz +
                p.z * texelFetch(u_weights, w + 2).xyz + p.w * texelFetch(u_weights, w + 3).xyz;
      }
      e[r] += r == 0u ? max(pair, vec3(0.0)) : pair;  // SH ringing must not make the irradiance negative
    }
  }
  for (uint r = 0u; r < rows; ++r) {
    const uint at = value_offset + r * vertex_count + j;
    gathered[at] = vec4(e[r], 0.0);
    indirect[at] += vec4(e[r], 0.0);
  }
}
