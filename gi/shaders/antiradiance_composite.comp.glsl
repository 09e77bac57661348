#version 450 core
// The antiradiance region's change added into the irradiance atlas (docs/antiradiance.md):
// for every atlas texel the region covers,
//   out(texel) = base(texel) + sum_k weight_k * delta[leaf_k]
// over the texel's (up to four) nearest leaves of its own surface (weights sum to 1: the
// paper's splatting of element values, §4.3, as a fixed blend). Texels outside the region
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
layout(std430, binding = 1) readonly buffer Delta { vec4 delta[]; };  // W/m^2 per leaf

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
  vec3 sum = imageLoad(base_image, coord).rgb;
  for (int k = 0; k < 4; ++k)
    if (b.leaves[k] >= 0) sum += b.weights[k] * delta[b.leaves[k]].rgb;
  imageStore(out_image, coord, vec4(max(sum, vec3(0.0)), 1.0));
}
