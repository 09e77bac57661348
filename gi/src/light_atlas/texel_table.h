#pragma once
// The texel gather's table of the atlas (texel_gather.h): per atlas texel, what the gather and
// its landing reads (texel_landing.h) know of it: its albedo and face, the valid texel an empty
// one is read as, and whether relocate_texel_samples moved its sample off its surface.
//   const gi::TexelTable t = gi::texel_table(bake_scene, layout).value();
//   for (std::uint32_t i : t.work) rho = t.albedo[i];

#include <engine/result.h>

#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace gi {

// Where a ray from a texel ends when it reads no texel (atlas texel ids lie below all three).
constexpr std::uint32_t kDark = 0xffffffffu;  // a ray into the surface, or nothing to read
constexpr std::uint32_t kSky = 0xfffffffeu;   // the ray escaped
constexpr std::uint32_t kBack = 0xfffffffdu;  // the back of a one-sided surface (black)

/// What the gather knows of every texel of the atlas.
struct TexelTable {
  int width = 0, height = 0;
  std::vector<std::uint32_t> work;      // valid texels in index order
  std::vector<glm::vec3> albedo;        // per atlas texel: hemispherical albedo of its material
  std::vector<glm::vec3> face;          // per atlas texel: unit geometric normal on the shading side
  std::vector<std::uint32_t> redirect;  // per atlas texel: itself when valid, else a valid neighbour or kDark
  float gap_m = 0.0f;                   // kGapTexels in metres
  float plane_m = 0.0f;                 // kOffPlaneTexels in metres
  std::vector<std::uint8_t> moved;      // per atlas texel: its sample lies off its triangle's plane
  float near_m = 0.0f;                  // one texel in metres
};

/// The table of `scene.texels`. Errors: a layout that is not the one the texels were
/// rasterized from (another size, mesh count or triangle count).
engine::Result<TexelTable> texel_table(const StaticBakeScene& scene, const AtlasLayout& layout);

}  // namespace gi
