#version 450 core
// PRM runtime sum (Szécsi et al. 2006, §5.2): for every pane element i of a touched tile,
//   E(texels[i]) = [base(texels[i])] + sum over the selected clusters k storing a block on
//                  that tile of weight_k * pane_k[i]
// written into the irradiance atlas at texel (x, y) = (texels[i] & 0xffff, texels[i] >> 16)
// (prm_gpu_pass.cpp packs each texel's coordinates once: a per-lane integer division by the
// width cost llvmpipe a scalar loop per invocation). Panes are sparse (prm_panes.h): a
// cluster stores only the atlas tiles its light reaches, so a light change dispatches only
// the chunks (eight slots) of the tiles its clusters light (and of the last change's tiles,
// written back to the base). Texel slots are grouped by tile, each tile padded to whole
// chunks with 0xffffffff (skipped). Work groups on a 2-D grid when one row would exceed 65535.
//
// Pane storage (prm_gpu_pass.cpp writes it), one of two encodings:
// - PRM_PANES_RGB9E5 defined (the default): one 32-bit word per element (three 9-bit
//   mantissas, one shared exponent); eight elements fill two uvec4s, a third fewer bytes.
// - otherwise half floats, three per element (R, G, B) packed tightly, two halves per uint
//   (low half first): eight elements (24 halves) fill three uvec4s exactly.
// One invocation sums one chunk of eight elements: per block two or three 16-byte texel
// fetches (llvmpipe gathers SSBO loads
// lane by lane and component by component, so bytes per load set the speed: the 4-byte
// loads of one element pair per invocation streamed a fifth of what a plain vec4 copy does,
// gi/benchmarks/prm_gpu_bench; buffer-texture fetches run as straight-line vector code and
// took the demo level's sum ~30% below the same loads from SSBOs, prm_relight_bench).
// Every pane was scaled by a power of two before packing so its largest value sits just
// below 2^15 (no overflow, full half precision); the inverse scale is folded into the
// weight, so weight * unpacked value is the true contribution.
//
// Several dispatches may cover one run when the panes live in several buffers (buffer size
// limit): the first writes (mode 0: from zero, mode 1: from base), later ones accumulate
// (mode 2: onto what out_image holds).

layout(local_size_x = 64) in;

// All four inputs are RGBA32UI buffer textures over the buffers prm_gpu_pass.cpp fills:
// llvmpipe fetches texels with straight-line vector code, where an SSBO load runs a loop
// over lanes and components.
// Texel coordinates x | y << 16, four per texel, slots grouped by tile.
layout(binding = 0) uniform usamplerBuffer texels;
// The bound pane buffer's uvec4s.
layout(binding = 1) uniform usamplerBuffer pane_blocks;
// Per selected block: (RGB weight x its pane's inverse packing scale as float bits, first
// uvec4 of the block in the bound pane buffer).
layout(binding = 2) uniform usamplerBuffer weights;
// Per chunk to sum: (its slot / 8, first weight, weight count, chunk index within its tile).
layout(binding = 3) uniform usamplerBuffer chunks;

layout(rgba32f, binding = 0) uniform image2D out_image;
layout(rgba32f, binding = 1) readonly uniform image2D base_image;

uniform uint u_first_chunk;  // this dispatch sums chunks[u_first_chunk .. + u_chunk_count)
uniform uint u_chunk_count;
uniform uint u_mode;  // 0: start from zero, 1: start from base_image, 2: accumulate

const uint kModeZero = 0u;
const uint kModeBase = 1u;
const uint kModeAccumulate = 2u;
const uint kBlock = 8u;  // elements per invocation
const uint kNoTexel = 0xffffffffu;

ivec2 coord_of(uint texel) { return ivec2(int(texel & 0xffffu), int(texel >> 16)); }

#ifdef PRM_PANES_RGB9E5
// One shared-exponent element: R, G, B 9-bit mantissas in bits 0-8, 9-17, 18-26, the
// exponent e in bits 27-31, value = mantissa x 2^(e - 24). The 2^-24 is folded into the
// weight (prm_gpu_pass.cpp), so this builds 2^e from its bits: integer ops and three
// int-to-float conversions.
vec3 rgb9e5(uint w) {
  const float scale = uintBitsToFloat((w >> 27) + 127u << 23);
  return vec3(float(w & 511u), float(w >> 9 & 511u), float(w >> 18 & 511u)) * scale;
}
#endif

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint index = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (index >= u_chunk_count) return;
  const uvec4 chunk = texelFetch(chunks, int(u_first_chunk + index));
  const uint block = chunk.x;

  uint texel[8];
  const uvec4 t0 = texelFetch(texels, int(2u * block));
  const uvec4 t1 = texelFetch(texels, int(2u * block + 1u));
  texel[0] = t0.x;
  texel[1] = t0.y;
  texel[2] = t0.z;
  texel[3] = t0.w;
  texel[4] = t1.x;
  texel[5] = t1.y;
  texel[6] = t1.z;
  texel[7] = t1.w;

  vec3 sum[8];
  for (uint e = 0u; e < kBlock; ++e) {
    sum[e] = vec3(0.0);
    if (texel[e] != kNoTexel) {
      if (u_mode == kModeBase)
        sum[e] = imageLoad(base_image, coord_of(texel[e])).xyz;
      else if (u_mode == kModeAccumulate)
        sum[e] = imageLoad(out_image, coord_of(texel[e])).xyz;
    }
  }
  for (uint k = 0u; k < chunk.z; ++k) {
    const uvec4 wk = texelFetch(weights, int(chunk.y + k));
    const vec3 weight = uintBitsToFloat(wk.xyz);
#ifdef PRM_PANES_RGB9E5
    const uint at = wk.w + 2u * chunk.w;  // 8 words: one RGB9E5 element each
    const uvec4 a = texelFetch(pane_blocks, int(at));
    const uvec4 b = texelFetch(pane_blocks, int(at + 1u));
    sum[0] += weight * rgb9e5(a.x);
    sum[1] += weight * rgb9e5(a.y);
    sum[2] += weight * rgb9e5(a.z);
    sum[3] += weight * rgb9e5(a.w);
    sum[4] += weight * rgb9e5(b.x);
    sum[5] += weight * rgb9e5(b.y);
    sum[6] += weight * rgb9e5(b.z);
    sum[7] += weight * rgb9e5(b.w);
#else
    const uint at = wk.w + 3u * chunk.w;  // 24 halves: R0 G0 B0 R1 ... B7
    const uvec4 a = texelFetch(pane_blocks, int(at));
    const uvec4 b = texelFetch(pane_blocks, int(at + 1u));
    const uvec4 c = texelFetch(pane_blocks, int(at + 2u));
    const vec2 h0 = unpackHalf2x16(a.x), h1 = unpackHalf2x16(a.y), h2 = unpackHalf2x16(a.z), h3 = unpackHalf2x16(a.w);
    const vec2 h4 = unpackHalf2x16(b.x), h5 = unpackHalf2x16(b.y), h6 = unpackHalf2x16(b.z), h7 = unpackHalf2x16(b.w);
    const vec2 h8 = unpackHalf2x16(c.x), h9 = unpackHalf2x16(c.y), h10 = unpackHalf2x16(c.z), h11 = unpackHalf2x16(c.w);
    sum[0] += weight * vec3(h0.x, h0.y, h1.x);
    sum[1] += weight * vec3(h1.y, h2.x, h2.y);
    sum[2] += weight * vec3(h3.x, h3.y, h4.x);
    sum[3] += weight * vec3(h4.y, h5.x, h5.y);
    sum[4] += weight * vec3(h6.x, h6.y, h7.x);
    sum[5] += weight * vec3(h7.y, h8.x, h8.y);
    sum[6] += weight * vec3(h9.x, h9.y, h10.x);
    sum[7] += weight * vec3(h10.y, h11.x, h11.y);
#endif
  }
  for (uint e = 0u; e < kBlock; ++e)
    if (texel[e] != kNoTexel) imageStore(out_image, coord_of(texel[e]), vec4(sum[e], 1.0));
}
