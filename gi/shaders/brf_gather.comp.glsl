#version 450 core
// One bounce at every vertex of every instance (Iwasaki et al. eq. 12), per receiver term k'
// (1 for a diffuse receiver, K for a glossy one):
//   E_r,0(x_j)  = sum over r's live sources s of max(0, sum_c w_s,c Phi_sr,(0,c)(x_j))   per rgb
//   E_r,k'(x_j) = sum over r's live sources s of sum_c w_s,c Phi_sr,(k',c)(x_j)          (k' >= 1, signed)
// (c over the source's channels k x N + i) written to gathered[] and added to indirect[]
// ([k' x V + j] per instance). One invocation per kGatherVertices (4) consecutive vertices of
// an instance (the instance's first invocation is its gather_first; found by binary search):
// each weight texel fetched serves 4 vertices (on llvmpipe the texel fetches are the cost;
// one vertex per invocation fetched 4 weight texels per Phi texel). Per vertex the sums are
// those of one invocation per vertex, term by term (bit for bit). The twin of gather() in
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
uniform uint u_invocation_total;

const uint kGatherVertices = 4u;  // brf_gpu_pass_detail.h kGatherVertices

// Receiver term r of vertices j0..j0+3 (those past the instance's last vertex read its last
// one and are not written) over the live sources: e[i] = sum over s of (clamped) the pair's row.
void gather_rows(uint j0, uint last, uint rows, uint r, uint live_first, uint live_count, out vec3 e0, out vec3 e1,
                 out vec3 e2, out vec3 e3) {
  e0 = vec3(0.0);
  e1 = vec3(0.0);
  e2 = vec3(0.0);
  e3 = vec3(0.0);
  const uint j1 = min(j0 + 1u, last), j2 = min(j0 + 2u, last), j3 = min(j0 + 3u, last);
  for (uint l = 0u; l < live_count; ++l) {
    const uvec4 src = texelFetch(u_live_sources, int(live_first + l));
    const uint q4 = src.z, stride = rows * q4;
    const uint a0 = src.y + (j0 * rows + r) * q4, a1 = src.y + (j1 * rows + r) * q4, a2 = src.y + (j2 * rows + r) * q4,
               a3 = src.y + (j3 * rows + r) * q4;
    vec3 p0 = vec3(0.0), p1 = vec3(0.0), p2 = vec3(0.0), p3 = vec3(0.0);
    for (uint q = 0u; q < q4; ++q) {
      const int w = int(src.x + 4u * q);
      const vec3 wx = texelFetch(u_weights, w).xyz, wy = texelFetch(u_weights, w + 1).xyz,
                 wz = texelFetch(u_weights, w + 2).xyz, ww = texelFetch(u_weights, w + 3).xyz;
      const vec4 f0 = texelFetch(u_phi, int(a0 + q)), f1 = texelFetch(u_phi, int(a1 + q)),
                 f2 = texelFetch(u_phi, int(a2 + q)), f3 = texelFetch(u_phi, int(a3 + q));
      p0 += f0.x * wx + f0.y * wy + f0.z * wz + f0.w * ww;
      p1 += f1.x * wx + f1.y * wy + f1.z * wz + f1.w * ww;
      p2 += f2.x * wx + f2.y * wy + f2.z * wz + f2.w * ww;
      p3 += f3.x * wx + f3.y * wy + f3.z * wz + f3.w * ww;
    }
    // SH ringing must not make the irradiance negative
    e0 += r == 0u ? max(p0, vec3(0.0)) : p0;
    e1 += r == 0u ? max(p1, vec3(0.0)) : p1;
    e2 += r == 0u ? max(p2, vec3(0.0)) : p2;
    e3 += r == 0u ? max(p3, vec3(0.0)) : p3;
  }
}

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint gi = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (gi >= u_invocation_total) return;
  // The last instance whose first invocation is <= gi (BrfInstance's gather_first: texel 1's w).
  uint lo = 0u, hi = u_instance_count - 1u;
  while (lo < hi) {
    const uint mid = (lo + hi + 1u) / 2u;
    if (texelFetch(u_instances, int(4u * mid + 1u)).w <= gi)
      lo = mid;
    else
      hi = mid - 1u;
  }
  const uint first = texelFetch(u_instances, int(4u * lo + 1u)).w;
  const uvec4 ia = texelFetch(u_instances, int(4u * lo + 2u)), ib = texelFetch(u_instances, int(4u * lo + 3u));
  const uint vertex_count = ia.z, live_first = ib.x, live_count = ib.y, value_offset = ib.z, rows = ib.w;
  const uint j0 = (gi - first) * kGatherVertices, last = vertex_count - 1u;
  for (uint r = 0u; r < rows; ++r) {
    vec3 e[4];
    gather_rows(j0, last, rows, r, live_first, live_count, e[0], e[1], e[2], e[3]);
    const uint at = value_offset + r * vertex_count + j0;
    for (uint i = 0u; i < kGatherVertices; ++i)
      if (j0 + i <= last) {
        gathered[at + i] = vec4(e[i], 0.0);
        indirect[at + i] += vec4(e[i], 0.0);
      }
  }
}
