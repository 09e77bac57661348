#version 450 core
// PRM panes coarser than the light atlas (docs/prm.md "Panes coarser than the atlas"): the
// pane sum (prm_sum.comp.glsl) is written at the panes' layout, then this pass reads it at
// every light-atlas texel the PaneUpsampler lists (gi/src/prm/pane_upsample.h):
//   E(fine) = [base(fine)] + sum over its taps t of weight_t * coarse(t)
// Taps stay inside the texel's own chart (no light crosses between surfaces); the atlas's
// gutter rings carry the mean of their filled neighbours' taps, as the light atlas is
// dilated. The upsampling is linear, so one pass per light change follows the K-sum.
// The taps are uploaded once (prm_gpu_pass.cpp); one invocation per fine texel. Work groups
// on a 2-D grid when one row would exceed 65535.

layout(local_size_x = 64) in;

// Per fine texel: (its coordinates x | y << 16, its first tap); one more entry ends the
// last texel's taps (.y = the tap count).
layout(std430, binding = 0) readonly buffer FineTexels { uvec2 fine_texels[]; };
// Per tap: (coarse texel coordinates x | y << 16, weight as float bits).
layout(std430, binding = 1) readonly buffer Taps { uvec2 taps[]; };

layout(rgba32f, binding = 0) writeonly uniform image2D out_image;
layout(rgba32f, binding = 1) readonly uniform image2D base_image;
layout(rgba32f, binding = 2) readonly uniform image2D coarse_image;

uniform uint u_count;     // fine texels
uniform uint u_has_base;  // 1: add base_image

ivec2 coord_of(uint texel) { return ivec2(int(texel & 0xffffu), int(texel >> 16)); }

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint k = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (k >= u_count) return;
  const uvec2 texel = fine_texels[k];
  const uint last = fine_texels[k + 1u].y;
  const ivec2 at = coord_of(texel.x);
  vec3 sum = vec3(0.0);
  for (uint t = texel.y; t < last; ++t) {
    const uvec2 tap = taps[t];
    sum += uintBitsToFloat(tap.y) * imageLoad(coarse_image, coord_of(tap.x)).xyz;
  }
  if (u_has_base != 0u) sum += imageLoad(base_image, at).xyz;
  imageStore(out_image, at, vec4(sum, 1.0));
}
