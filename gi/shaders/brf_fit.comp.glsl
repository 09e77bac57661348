#version 450 core
// Least-squares weights of every instance's light over its PCA basis (Iwasaki et al. §5.2,
// eq. 14), per term k and the three RGB channels at once: b_k = Psi^T L_k, w_k = A^-1 b_k.
// One work group per instance; an invocation per channel (k, i). L_k = reflect(E_k): albedo
// x E_0 for the irradiance, specular x E_k for the glossy terms, with E = gathered (u_mode 0:
// the last bounce) or incoming + indirect (u_mode 1: the total light, for the static world).
// The twin of brf_fit_rgb, summed in float instead of double. Writes one rgb vec4 per channel
// (k x N + i); the pads up to a multiple of 4 keep the zeros the CPU uploaded.

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

const uint kMaxChannels = 1024u;  // 64 basis functions x 16 terms (brf_gpu_pass.cpp rejects more)
shared vec3 s_b[kMaxChannels];

void main() {
  const BrfInstance inst = instances[gl_WorkGroupID.x];
  const BrfModel m = models[inst.model];
  const uint nb = m.basis_count, nv = m.vertex_count, nc = nb * inst.terms;
  for (uint ch = gl_LocalInvocationIndex; ch < nc; ch += gl_WorkGroupSize.x) {
    const uint term = ch / nb, i = ch - term * nb;
    const uint psi_row = m.psi_offset + i * nv;
    const vec3 reflectance = term == 0u ? inst.albedo.xyz : inst.specular.xyz;
    const uint first = inst.value_offset + term * nv;
    vec3 b = vec3(0.0);
    for (uint j = 0u; j < nv; ++j) {
      const uint gv = first + j;
      const vec3 e = u_mode == 0u ? gathered[gv].xyz : incoming[gv].xyz + indirect[gv].xyz;
      b += psi[psi_row + j] * (reflectance * e);
    }
    s_b[ch] = b;
  }
  barrier();
  for (uint ch = gl_LocalInvocationIndex; ch < nc; ch += gl_WorkGroupSize.x) {
    const uint term = ch / nb, r = ch - term * nb;
    vec3 w = vec3(0.0);
    for (uint q = 0u; q < nb; ++q) w += a_inverse[m.ainv_offset + r * nb + q] * s_b[term * nb + q];
    weights[inst.weight_offset + ch] = vec4(w, 0.0);
  }
}
