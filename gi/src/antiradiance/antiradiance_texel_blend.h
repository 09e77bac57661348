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

/// A texel's atlas value after the region's change (antiradiance_composite.comp.glsl's rule),
/// per channel: light the change adds is added (atlas + change). Light it takes away is taken
/// as added where `share` is 0 (clamped at 0), and as the share of the leaves' own light they
/// lose where `share` is 1 (atlas x (1 + change / baseline), at least 0), blended between. The
/// runtime sets share 1 at near-door visibility's receivers, whose baseline is their own
/// ray-traced light: a texel darkens by the fraction its leaves darken, whatever the atlas's
/// absolute level. Adding their loss drove texels whose atlas is darker than the leaves' baseline
/// below 0 (the corridor's cyan texels, docs/antiradiance.md). Antiradiance's own leaves keep 0:
/// their baseline is its leaky solve's, and the share of it scored worse (0.204 against 0.182 of
/// the level on the corridor). `change`, `baseline` and `share` are the texel's blended leaf
/// values; a baseline of 0 or less takes the sum.
glm::vec3 composite_change(const glm::vec3& atlas, const glm::vec3& change, const glm::vec3& baseline, float share);

/// The floor the per-leaf output sets whatever the solver computes: a per-texel field
/// (indexed by atlas texel, like blends' texel) projected onto the leaves and blended back.
/// Each leaf gets the mean of `per_texel` over the texels of `blends` with `use` set whose
/// heaviest leaf it is (the leaf's area average, sampled at the texels); each such texel
/// then the blend of those means over its leaves that got one (weights renormalized; 0 when
/// none did). Returned per atlas texel (`per_texel.size()`), 0 at texels not used.
std::vector<glm::vec3> project_through_leaves(std::span<const AntiradianceTexelBlend> blends,
                                              std::span<const glm::vec3> per_texel, std::span<const std::uint8_t> use,
                                              std::size_t leaf_count);

}  // namespace gi
