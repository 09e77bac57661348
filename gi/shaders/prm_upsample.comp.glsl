#version 450 core
// PRM panes coarser than the light atlas (docs/prm.md "Panes coarser than the atlas"): the
// pane sum (prm_sum.comp.glsl) is written at the panes' layout, then this pass reads it at
// every light-atlas texel the PaneUpsampler lists (gi/src/prm/pane_upsample.h), in passes:
//   u_mode 0 (reads): E(fine) = sum over the 2 x 2 coarse texels at its origin of weight * coarse
//   u_mode 1 (one gutter ring): E(fine) = mean of its filled 8-neighbours' E (the neighbour mask)
//   u_mode 2 (base): E(fine) += base(fine) over the reads, then the ring texels (u_reads of them)
// Taps stay inside the texel's own chart (no light crosses between surfaces); the atlas's
// gutter rings are filled as the light atlas is dilated, ring after ring. The upsampling is
// linear, so one set of passes per light change follows the K-sum. The records are uploaded
// once (prm_gpu_pass.cpp): 16 bytes per read, 8 per ring texel. One invocation per record;
// work groups on a 2-D grid when one row would exceed 65535.

layout(local_size_x = 64) in;

// Per read: (fine x | y << 16, coarse origin (x + 1) | (y + 1) << 16, weights 0 | 1 << 16,
// weights 2 | 3 << 16), weights as 16-bit fractions of 65535.
layout(std430, binding = 0) readonly buffer Reads { uvec4 reads[]; };
// Per ring texel: (fine x | y << 16, its neighbour mask).
layout(std430, binding = 1) readonly buffer Rings { uvec2 rings[]; };

layout(rgba32f, binding = 0) uniform image2D out_image;
layout(rgba32f, binding = 1) readonly uniform image2D base_image;
layout(rgba32f, binding = 2) readonly uniform image2D coarse_image;

uniform uint u_first;  // first record
uniform uint u_count;  // records of this dispatch
uniform uint u_mode;   // 0 reads, 1 a ring, 2 the base over the reads and the rings
uniform uint u_reads;  // reads (u_mode 2: record k >= u_reads is ring texel k - u_reads)

const ivec2 kNeighbour[8] = ivec2[8](ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1), ivec2(-1, 0), ivec2(1, 0), ivec2(-1, 1),
                                     ivec2(0, 1), ivec2(1, 1));

ivec2 coord_of(uint texel) { return ivec2(int(texel & 0xffffu), int(texel >> 16)); }

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint k = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (k >= u_count) return;
  const uint r = u_first + k;
  if (u_mode == 0u) {
    const uvec4 read = reads[r];
    const ivec2 origin = coord_of(read.y) - ivec2(1);
    const float w[4] = float[4](float(read.z & 0xffffu) / 65535.0, float(read.z >> 16) / 65535.0,
                                float(read.w & 0xffffu) / 65535.0, float(read.w >> 16) / 65535.0);
    vec3 sum = vec3(0.0);
    for (int t = 0; t < 4; ++t)
      if (w[t] > 0.0) sum += w[t] * imageLoad(coarse_image, origin + ivec2(t & 1, t >> 1)).xyz;
    imageStore(out_image, coord_of(read.x), vec4(sum, 1.0));
  } else if (u_mode == 1u) {
    const uvec2 ring = rings[r];
    const ivec2 at = coord_of(ring.x);
    vec3 sum = vec3(0.0);
    float n = 0.0;
    for (int t = 0; t < 8; ++t)
      if ((ring.y & (1u << uint(t))) != 0u) {
        sum += imageLoad(out_image, at + kNeighbour[t]).xyz;
        n += 1.0;
      }
    imageStore(out_image, at, vec4(sum / n, 1.0));
  } else {
    const ivec2 at = coord_of(r < u_reads ? reads[r].x : rings[r - u_reads].x);
    imageStore(out_image, at, vec4(imageLoad(out_image, at).xyz + imageLoad(base_image, at).xyz, 1.0));
  }
}
