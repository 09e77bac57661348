#version 450 core
// The dynamic objects' bounce onto the static world (basis radiance fields, the world as a
// receiver): out_image already holds the static irradiance atlas (light atlas [+ PRM]);
// every static receiver texel i keeps (1 - occlusion[i]) of it (the share of its incoming
// light the objects block, BrfResult::static_occlusion) and adds the objects' irradiance
// bounce[i].xyz, at atlas texel texels[i] (x = t % width, y = t / width). One invocation per receiver; each texel
// appears once, so there are no write races.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Texels { uint texels[]; };
layout(std430, binding = 1) readonly buffer Bounce { vec4 bounce[]; };
layout(std430, binding = 2) readonly buffer Occlusion { float occlusion[]; };
layout(rgba32f, binding = 0) uniform image2D out_image;

uniform uint u_count;
uniform uint u_atlas_width;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  const uint t = texels[i];
  const ivec2 at = ivec2(int(t % u_atlas_width), int(t / u_atlas_width));
  const vec4 base = imageLoad(out_image, at);
  imageStore(out_image, at, vec4(base.rgb * (1.0 - occlusion[i]) + bounce[i].xyz, base.a));
}
