#version 450 core
// PRM runtime sum (Szécsi et al. 2006, §5.2): for every pane element i,
//   E(texels[i]) = [base(texels[i])] + sum over the selected clusters k of weight_k * pane_k[i]
// written into the irradiance atlas at texel (texels[i] % width, texels[i] / width). One
// invocation per pane element; work groups on a 2-D grid when one row would exceed 65535.
//
// Pane storage (prm_gpu_pass.cpp writes it): each pane is a run of half floats, three per
// element (R, G, B) packed tightly, two halves per uint (low half first): element i's halves
// are 3i..3i+2, so the pair of elements (2j, 2j+1) fills words 3j..3j+2 exactly. One
// invocation sums one pair: three word loads for two elements (llvmpipe gathers SSBO loads
// lane by lane, so loads per element set the speed). Every pane was scaled by a power of two before packing so its
// largest value sits just below 2^15 (no overflow, full half precision); the inverse scale
// is folded into the weight, so weight * unpacked value is the true contribution.
//
// Several dispatches may cover one run when the panes live in several buffers (SSBO size
// limit): the first writes (mode 0: from zero, mode 1: from base), later ones accumulate
// (mode 2: onto what out_image holds).

layout(local_size_x = 64) in;

struct PaneWeight {
  vec3 weight;       // RGB weight of the cluster times its pane's inverse packing scale
  uint pane_offset;  // first word of the cluster's pane in the bound pane buffer
};

layout(std430, binding = 0) readonly buffer Texels { uint texels[]; };
layout(std430, binding = 1) readonly buffer Panes { uint pane_words[]; };
layout(std430, binding = 2) readonly buffer Weights { PaneWeight weights[]; };

layout(rgba32f, binding = 0) uniform image2D out_image;
layout(rgba32f, binding = 1) readonly uniform image2D base_image;

uniform uint u_element_count;  // T: pane elements
uniform uint u_atlas_width;
uniform uint u_first_weight;   // this dispatch sums weights[u_first_weight .. + u_weight_count)
uniform uint u_weight_count;
uniform uint u_mode;           // 0: start from zero, 1: start from base_image, 2: accumulate

const uint kModeZero = 0u;
const uint kModeBase = 1u;
const uint kModeAccumulate = 2u;

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint pair = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  const uint first = 2u * pair;
  if (first >= u_element_count) return;
  const bool has_second = first + 1u < u_element_count;

  const uint texel0 = texels[first];
  const uint texel1 = has_second ? texels[first + 1u] : texel0;
  const ivec2 coord0 = ivec2(int(texel0 % u_atlas_width), int(texel0 / u_atlas_width));
  const ivec2 coord1 = ivec2(int(texel1 % u_atlas_width), int(texel1 / u_atlas_width));

  vec3 sum0 = vec3(0.0);
  vec3 sum1 = vec3(0.0);
  if (u_mode == kModeBase) {
    sum0 = imageLoad(base_image, coord0).xyz;
    sum1 = imageLoad(base_image, coord1).xyz;
  } else if (u_mode == kModeAccumulate) {
    sum0 = imageLoad(out_image, coord0).xyz;
    sum1 = imageLoad(out_image, coord1).xyz;
  }
  for (uint k = 0u; k < u_weight_count; ++k) {
    const PaneWeight w = weights[u_first_weight + k];
    const uint word = w.pane_offset + 3u * pair;  // the pair's six halves: R0 G0 | B0 R1 | G1 B1
    const vec2 a = unpackHalf2x16(pane_words[word]);
    const vec2 b = unpackHalf2x16(pane_words[word + 1u]);
    const vec2 c = unpackHalf2x16(pane_words[word + 2u]);
    sum0 += w.weight * vec3(a.x, a.y, b.x);
    sum1 += w.weight * vec3(b.y, c.x, c.y);
  }
  imageStore(out_image, coord0, vec4(sum0, 1.0));
  if (has_second) imageStore(out_image, coord1, vec4(sum1, 1.0));
}
