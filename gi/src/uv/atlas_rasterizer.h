#pragma once
// Rasterizes an atlas layout: for every texel, the world-space surface point it stands for
// (the sample a baker lights), its shading normal and the triangle that owns it.
//   gi::AtlasTexels texels = gi::rasterize_atlas(layout.value(), inputs);
//   if (texels.valid[texels.index(x, y)]) bake_at(texels.position[texels.index(x, y)]);
//
// Coverage rule (deterministic):
// - Inside: the texel centre lies inside or on the triangle in texel space (uv1 x size).
//   Among several such triangles the first in (mesh, triangle) order owns the texel.
// - Conservative: otherwise, when a triangle touches the texel square (closed, within 1e-4
//   texel), the texel samples the point of that triangle closest to its centre. Among several
//   such triangles the closest wins, then the first in (mesh, triangle) order.
// - With inset_texels > 0, either sample then moves that far inside its triangle when it
//   lies closer to an edge (towards the centroid): a sample on a chart's border would sit
//   on the line where the next surface starts, and rays from it would slip behind that
//   surface.
// - Inside always beats Conservative. So every triangle's texel under its uv centroid is
//   valid and owned by a triangle of the same chart (charts never share texels); a triangle
//   too thin to own a texel of its own (a sliver next to others) reads its chart neighbour's
//   sample there. An isolated tiny or degenerate triangle always owns a sample.

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace gi {

enum class TexelCoverage : std::uint8_t { Empty, Conservative, Inside };

/// Per-texel samples of an atlas, each array width x height, texel (x, y) at y * width + x.
struct AtlasTexels {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> position;      ///< World-space sample point, metres (0 where empty).
  std::vector<glm::vec3> normal;        ///< Unit shading normal (interpolated; 0 where empty).
  std::vector<std::uint8_t> valid;      ///< 1 where a triangle covers the texel.
  std::vector<TexelCoverage> coverage;  ///< How it is covered.
  std::vector<std::int32_t> mesh;       ///< Owning input mesh, -1 where empty.
  std::vector<std::int32_t> triangle;   ///< Owning triangle of that mesh, -1 where empty.
  std::vector<std::int32_t> chart;      ///< Chart of the owning triangle, -1 where empty.

  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
  }
};

/// Samples every texel of `layout`. Precondition: `inputs` are the meshes the layout was
/// built from (same count and vertex counts).
AtlasTexels rasterize_atlas(const AtlasLayout& layout, std::span<const AtlasInputMesh> inputs,
                            float inset_texels = 0.0f);

}  // namespace gi
