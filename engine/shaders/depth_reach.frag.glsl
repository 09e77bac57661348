#version 450 core
// Depth pre-pass with light reach (engine/light_reach.h): writes each pixel's stencil with
// the light mask of the voxel its surface lies in; the forward pass then shades the pixel
// once, with the program and light list of that mask (stencil test EQUAL).
// ALPHA_TEST 1: MASK materials discard their cut-out texels (depth_only.frag.glsl).
#extension GL_ARB_shader_stencil_export : require
#include "material_common.glsl"
in vec3 v_world;
layout(binding = 9) uniform usampler3D u_reach;
uniform vec3 u_reach_origin;
uniform float u_reach_inv_voxel;
uniform int u_reach_all;  // outside the grid: every light

void main() {
  alpha_test();
  ivec3 v = ivec3(floor((v_world - u_reach_origin) * u_reach_inv_voxel));
  ivec3 dims = textureSize(u_reach, 0);
  int mask = u_reach_all;
  if (all(greaterThanEqual(v, ivec3(0))) && all(lessThan(v, dims))) mask = int(texelFetch(u_reach, v, 0).r);
  gl_FragStencilRefARB = mask;
}
