#version 450 core
// The objects' light on static-world receivers: for every receiver inside at least one
// source's outermost field sphere,
//   E(t) = sum over those sources s of max(0, sum_c w_s,c Phi_s,c(t))   per rgb
// with w the fit of the source's total light (all its terms, channels c = k x N + i)
// (brf_fit.comp.glsl, mode 1). One invocation per such receiver; its entries list the sources
// in instance order, as brf_interreflect adds them.

#include "brf_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Touched { uvec4 touched[]; };  // (receiver, first entry, entry count, 0)
// (first weight vec4, first Phi vec4, C4 / 4, source)
layout(std430, binding = 1) readonly buffer Entries { uvec4 entries[]; };
layout(std430, binding = 2) readonly buffer Instances { BrfInstance instances[]; };
layout(std430, binding = 3) readonly buffer Models { BrfModel models[]; };
layout(std430, binding = 4) readonly buffer Weights { vec4 weights[]; };       // rgb per channel, pads 0
layout(std430, binding = 5) readonly buffer StaticPhi { vec4 static_phi[]; };  // rows of C4 floats, pads 0
layout(std430, binding = 6) writeonly buffer StaticOut { vec4 static_out[]; };

uniform uint u_touched_count;

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint k = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (k >= u_touched_count) return;
  const uvec4 t = touched[k];
  vec3 e = vec3(0.0);
  for (uint l = 0u; l < t.z; ++l) {
    const uvec4 src = entries[t.y + l];
    const uint q4 = src.z;
    vec3 pair = vec3(0.0);
    for (uint q = 0u; q < q4; ++q) {
      const vec4 p = static_phi[src.y + q];
      const uint w = src.x + 4u * q;
      pair += p.x * weights[w].xyz + p.y * weights[w + 1u].xyz + p.z * weights[w + 2u].xyz + p.w * weights[w + 3u].xyz;
    }
    e += max(pair, vec3(0.0));
  }
  static_out[t.x] = vec4(e, 0.0);
}
