#pragma once
// How an antiradiance region's per-leaf result reaches the light atlas (docs/antiradiance.md,
// deviation 7): every atlas texel of a static instance with leaves gets its up-to-four
// nearest leaves of that instance facing its way (normals within ~45 degrees), weighted by
// 1 / (d^2 + (r/2)^2) of the leaf radius r, weights summing to 1. The runtime composites
// with these (antiradiance_composite.comp.glsl); the sweep evaluates the region at atlas
// texels with the same blend, so it measures what the renderer adds.
//   auto blends = gi::antiradiance_texel_blends(region.hierarchy(), input, layout);
//   glm::vec3 e = gi::blend_leaves(blends[k], per_leaf);

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <gi/bake_input.h>

#include "antiradiance/element_hierarchy.h"
#include "uv/atlas_layout.h"

namespace gi {

/// One covered atlas texel: its leaves (-1: none) and blend weights (std430 TexelBlend of
/// antiradiance_composite.comp.glsl: 48 bytes).
struct AntiradianceTexelBlend {
  std::uint32_t texel = 0, pad0 = 0, pad1 = 0, pad2 = 0;
  glm::ivec4 leaves{-1};
  glm::vec4 weights{0.0f};
};

/// The blends of every covered texel of `layout` (the atlas of `input`'s static instances),
/// in texel order.
std::vector<AntiradianceTexelBlend> antiradiance_texel_blends(const ElementHierarchy& h, const BakeInput& input,
                                                              const AtlasLayout& layout);

/// sum_k weights[k] x per_leaf[leaves[k]].
glm::vec3 blend_leaves(const AntiradianceTexelBlend& b, std::span<const glm::vec3> per_leaf);

}  // namespace gi
