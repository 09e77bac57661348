#version 450 core
// Least-squares weights of every instance's radiosity over its PCA basis (Iwasaki et al.
// §5.2, eq. 14), per RGB channel: b = Psi^T L, w = A^-1 b. One work group per instance.
// L = albedo x gathered (u_mode 0: the last bounce) or albedo x (incoming + indirect)
// (u_mode 1: the total radiosity, for the static world). The twin of brf_fit_rgb, summed in
// float instead of double.

#include "brf_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Instances { BrfInstance instances[]; };
layout(std430, binding = 1) readonly buffer Models { BrfModel models[]; };
layout(std430, binding = 2) readonly buffer Psi { float psi[]; };
layout(std430, binding = 3) readonly buffer AInverse { float a_inverse[]; };
layout(std430, binding = 4) readonly buffer Incoming { vec4 incoming[]; };
layout(std430, binding = 5) readonly buffer Gathered { vec4 gathered[]; };
layout(std430, binding = 6) readonly buffer Indirect { vec4 indirect[]; };
layout(std430, binding = 7) writeonly buffer Weights { float weights[]; };

uniform uint u_mode;

const uint kMaxBasis = 64u;  // brf_gpu_pass.cpp rejects larger bases
shared float s_b[3u * kMaxBasis];

void main() {
  const BrfInstance inst = instances[gl_WorkGroupID.x];
  const BrfModel m = models[inst.model];
  const uint nb = m.basis_count, nv = m.vertex_count;
  for (uint k = gl_LocalInvocationIndex; k < 3u * nb; k += gl_WorkGroupSize.x) {
    const uint c = k / nb, i = k % nb;
    const uint psi_row = m.psi_offset + i * nv;
    float b = 0.0;
    for (uint j = 0u; j < nv; ++j) {
      const uint gv = inst.vertex_offset + j;
      const float e = u_mode == 0u ? gathered[gv][c] : incoming[gv][c] + indirect[gv][c];
      b += psi[psi_row + j] * (inst.albedo[c] * e);
    }
    s_b[k] = b;
  }
  barrier();
  for (uint k = gl_LocalInvocationIndex; k < 3u * nb; k += gl_WorkGroupSize.x) {
    const uint c = k / nb, r = k % nb;
    float w = 0.0;
    for (uint q = 0u; q < nb; ++q) w += a_inverse[m.ainv_offset + r * nb + q] * s_b[c * nb + q];
    weights[inst.weight_offset + k] = w;
  }
}
