#pragma once
// The light-atlas parameterization (uv1 / TEXCOORD_1) of a set of static world-space meshes:
// charts of near-coplanar triangles, projected at a texel density, packed into one atlas.
//   auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(asset), {.texels_per_metre = 32.0f});
//   if (!layout) std::cerr << layout.error().to_string() << '\n';
//
// Conventions
// - Texel (x, y) is element y * width + x of every atlas image (row 0 first, as glTexImage2D
//   uploads it); its centre is at uv ((x + 0.5) / width, (y + 0.5) / height). uv1 is not
//   flipped: v grows with the row index.
// - Each chart owns a footprint rectangle of whole texels; footprints are `padding_texels`
//   apart and at least that far from the atlas border. Every texel a chart's triangles touch
//   lies inside its footprint, so with padding >= 2 and one dilation pass (atlas_dilation.h),
//   bilinear reads anywhere inside a triangle only see texels of its own chart.
// - A vertex used by triangles of several charts is split: AtlasMeshUv gives each mesh its
//   own vertex list (`source_vertex`, `uv1`) and index buffer (same triangle order as the
//   input). Vertex i < input vertex count keeps index i (with the uv of the first chart, in
//   triangle order, that uses it); copies for further charts are appended in order of first
//   use. Vertices no triangle uses keep uv (0, 0).

#include <engine/result.h>

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "uv/atlas_input.h"

namespace gi {

struct AtlasSettings {
  float texels_per_metre = 32.0f;  ///< Requested density (0 < d <= kMaxTexelsPerMetre).
  int padding_texels = 2;          ///< Gutter between charts and at the border (0..64; >= 2 for seamless bilinear).
  int max_atlas_size = 4096;       ///< Largest width and height tried (16..16384).
  float chart_max_angle_degrees = 20.0f;  ///< Near-coplanarity threshold of charting (0 < a < 90).
  float weld_distance_m = 1e-4f;          ///< Positions closer than this are one point (>= 0).
  bool rotate_charts = true;              ///< Rotate charts to their minimal-area rectangle.
};

/// Densities above this (0.1 mm texels) are rejected as absurd input.
inline constexpr float kMaxTexelsPerMetre = 1.0e4f;

/// One chart placed in the atlas.
struct AtlasChart {
  std::uint32_t mesh = 0;              ///< Index into AtlasLayout::meshes (= the input index).
  glm::ivec2 origin{0};                ///< Min texel of the footprint.
  glm::ivec2 size{0};                  ///< Footprint size, texels.
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  ///< Unit projection axis, world space.
  std::uint32_t triangle_count = 0;
  double area_m2 = 0.0;  ///< World-space area of its triangles.
};

/// The atlas parameterization of one input mesh (see the conventions above).
struct AtlasMeshUv {
  std::int64_t id = -1;                       ///< The input's id.
  std::vector<std::uint32_t> indices;         ///< 3 per triangle, input order, into source_vertex / uv1.
  std::vector<std::uint32_t> source_vertex;   ///< Output vertex -> input vertex.
  std::vector<glm::vec2> uv1;                 ///< Normalized atlas coordinates in [0, 1], per output vertex.
  std::vector<std::uint32_t> triangle_chart;  ///< Chart (index into AtlasLayout::charts) per triangle.
};

struct AtlasLayout {
  int width = 0;                            ///< Texels.
  int height = 0;                           ///< Texels.
  float texels_per_metre = 0.0f;            ///< Achieved density (may be below the request, never above).
  float requested_texels_per_metre = 0.0f;  ///< What the settings asked for.
  int padding_texels = 0;
  std::vector<AtlasChart> charts;   ///< In input order, then by seed triangle.
  std::vector<AtlasMeshUv> meshes;  ///< One per input, same order.

  /// True when the charts did not fit max_atlas_size at the requested density.
  bool density_reduced() const { return texels_per_metre < requested_texels_per_metre; }
};

/// Charts, packs and parameterizes `inputs`. Errors (with a message naming the problem) for
/// invalid inputs (see validate_atlas_inputs), out-of-range settings, or charts that cannot
/// fit max_atlas_size at any density. When the charts do not fit at the requested density,
/// the density is lowered until they do and the achieved density is reported.
/// Deterministic: the same inputs and settings give the same layout.
engine::Result<AtlasLayout> build_atlas_layout(std::span<const AtlasInputMesh> inputs,
                                               const AtlasSettings& settings = {});

/// The layout every baker of the static world builds: build_atlas_layout of
/// atlas_inputs_from(input) at `texels_per_metre`, other settings at their defaults.
engine::Result<AtlasLayout> static_world_layout(const BakeInput& input, float texels_per_metre);

}  // namespace gi
