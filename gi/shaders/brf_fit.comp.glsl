#version 450 core
// Least-squares weights of every instance's radiosity over its PCA basis (Iwasaki et al.
// §5.2, eq. 14), the three RGB channels at once: b = Psi^T L, w = A^-1 b. One work group per
// instance; an invocation per basis function. L = albedo x gathered (u_mode 0: the last
// bounce) or albedo x (incoming + indirect) (u_mode 1: the total radiosity, for the static
// world). The twin of brf_fit_rgb, summed in float instead of double. Writes one rgb vec4 per
// basis function; the pads up to a multiple of 4 keep the zeros the CPU uploaded.

#include "brf_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Instances { BrfInstance instances[]; };
layout(std430, binding = 1) readonly buffer Models { BrfModel models[]; };
layout(std430, binding = 2) readonly buffer Psi { float psi[]; };
layout(std430, binding = 3) readonly buffer AInverse { float a_inverse[]; };
layout(std430, binding = 4) readonly buffer Incoming { vec4 incoming[]; };
layout(std430, binding = 5) readonly buffer Gathered { vec4 gathered[]; };
layout(std430, binding = 6) readonly buffer Indirect { vec4 indirect[]; };
layout(std430, binding = 7) writeonly buffer Weights { vec4 weights[]; };

uniform uint u_mode;

const uint kMaxBasis = 64u;  // brf_gpu_pass.cpp rejects larger bases
shared vec3 s_b[kMaxBasis];

void main() {
  const BrfInstance inst = instances[gl_WorkGroupID.x];
  const BrfModel m = models[inst.model];
  const uint nb = m.basis_count, nv = m.vertex_count;
  for (uint i = gl_LocalInvocationIndex; i < nb; i += gl_WorkGroupSize.x) {
    const uint psi_row = m.psi_offset + i * nv;
    vec3 b = vec3(0.0);
    for (uint j = 0u; j < nv; ++j) {
      const uint gv = inst.vertex_offset + j;
      const vec3 e = u_mode == 0u ? gathered[gv].xyz : incoming[gv].xyz + indirect[gv].xyz;
      b += psi[psi_row + j] * (inst.albedo.xyz * e);
    }
    s_b[i] = b;
  }
  barrier();
  for (uint r = gl_LocalInvocationIndex; r < nb; r += gl_WorkGroupSize.x) {
    vec3 w = vec3(0.0);
    for (uint q = 0u; q < nb; ++q) w += a_inverse[m.ainv_offset + r * nb + q] * s_b[q];
    weights[inst.weight_offset + r] = vec4(w, 0.0);
  }
}
