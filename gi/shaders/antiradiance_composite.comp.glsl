#version 450 core
// The antiradiance region's change composited into the irradiance atlas (docs/antiradiance.md):
// for every atlas texel the region covers, with d, b and s the blends (sum_k weight_k x) of
// the leaves' change, baseline.rgb and share (baseline.w) over the texel's (up to four)
// nearest leaves of its own surface (weights sum to 1: the paper's splatting of element
// values, §4.3, as a fixed blend), per channel
//   out = base + d                                   where d adds light (or b <= 0)
//   out = mix(max(base + d, 0), base * clamp(1 + d / b, 0, 1), s)   where d takes light away
// (composite_change in antiradiance_texel_blend.h, its CPU twin: s is 1 at near-door
// visibility's receivers, a loss taken as the share of their light they lose). Texels outside the region
// were copied from base before this pass. One invocation per covered texel.

layout(local_size_x = 64) in;

struct TexelBlend {
  uint texel;  // y * width + x
  uint pad0;
  uint pad1;
  uint pad2;
  ivec4 leaves;  // -1: unused
  vec4 weights;
};

layout(std430, binding = 0) readonly buffer Blends { TexelBlend blends[]; };
layout(std430, binding = 1) readonly buffer Delta { vec4 delta[]; };        // W/m^2 per leaf
layout(std430, binding = 2) readonly buffer Baseline { vec4 baseline[]; };  // rgb: the change's zero, W/m^2; w: share

layout(rgba32f, binding = 0) uniform image2D out_image;
layout(rgba32f, binding = 1) readonly uniform image2D base_image;

uniform uint u_count;
uniform uint u_width;

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint i = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (i >= u_count) return;
  const TexelBlend b = blends[i];
  const ivec2 coord = ivec2(int(b.texel % u_width), int(b.texel / u_width));
  const vec3 atlas = imageLoad(base_image, coord).rgb;
  vec3 d = vec3(0.0);
  vec4 zero = vec4(0.0);
  for (int k = 0; k < 4; ++k)
    if (b.leaves[k] >= 0) {
      d += b.weights[k] * delta[b.leaves[k]].rgb;
      zero += b.weights[k] * baseline[b.leaves[k]];
    }
  const float share = clamp(zero.w, 0.0, 1.0);
  vec3 outv;
  for (int c = 0; c < 3; ++c) {
    const float added = max(atlas[c] + d[c], 0.0);
    outv[c] =
        (d[c] >= 0.0 || !(zero[c] > 0.0)) ? added : mix(added, atlas[c] * clamp(1.0 + d[c] / zero[c], 0.0, 1.0), share);
  }
  imageStore(out_image, coord, vec4(outv, 1.0));
}
