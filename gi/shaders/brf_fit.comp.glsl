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
// The arrays read in the loops are buffer textures (llvmpipe, Mesa 22: a texel fetch is one
// gather, an SSBO load a loop over the SIMD lanes): unit 0 Psi, 1 A^-1 (R32F), 2 incoming,
// 3 gathered, 4 indirect (RGBA32F).
layout(binding = 0) uniform samplerBuffer u_psi;
layout(binding = 1) uniform samplerBuffer u_a_inverse;
layout(binding = 2) uniform samplerBuffer u_incoming;
layout(binding = 3) uniform samplerBuffer u_gathered;
layout(binding = 4) uniform samplerBuffer u_indirect;
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
      const vec3 e = u_mode == 0u ? texelFetch(u_gathered, int(gv)).xyz
                                  : texelFetch(u_incoming, int(gv)).xyz + texelFetch(u_indirect, int(gv)).xyz;
      b += texelFetch(u_psi, int(psi_row + j)).x * (reflectance * e);
    }
    s_b[ch] = b;
  }
  barrier();
  for (uint ch = gl_LocalInvocationIndex; ch < nc; ch += gl_WorkGroupSize.x) {
    const uint term = ch / nb, r = ch - term * nb;
    vec3 w = vec3(0.0);
    for (uint q = 0u; q < nb; ++q) w += texelFetch(u_a_inverse, int(m.ainv_offset + r * nb + q)).x * s_b[term * nb + q];
    weights[inst.weight_offset + ch] = vec4(w, 0.0);
  }
}
