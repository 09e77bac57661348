#pragma once
// Charting: splits one world-space mesh into charts of connected, near-coplanar triangles and
// gives each chart a planar projection (metres) with a minimal-area bounding rectangle.
//   std::vector<gi::Chart> charts = gi::build_charts(mesh, 0, {.max_angle_degrees = 20.0f});
//   glm::vec2 m = charts[0].project_m(mesh.positions[i]);  // metres from the chart's corner

#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

#include "uv/atlas_input.h"

namespace gi {

struct ChartingSettings {
  /// A triangle joins a chart when its normal is within this angle of the chart's seed
  /// triangle's normal (and it shares an edge with a triangle of the chart).
  float max_angle_degrees = 20.0f;
  /// Two vertices are the same point when closer than this (meshes duplicate vertices per
  /// face, so connectivity comes from positions, not from shared indices).
  float weld_distance_m = 1e-4f;
  /// Rotate each chart in its plane to the minimal-area bounding rectangle (then make it
  /// wider than tall); off: the rectangle follows the plane basis.
  bool rotate_to_min_area = true;
};

/// A set of triangles of one mesh projected onto one plane.
struct Chart {
  std::uint32_t mesh = 0;                ///< Index of the input mesh.
  std::vector<std::uint32_t> triangles;  ///< Triangle indices into the mesh, ascending.
  glm::vec3 normal{0.0f, 0.0f, 1.0f};    ///< Unit projection axis (area-weighted mean normal).
  glm::vec3 axis_u{1.0f, 0.0f, 0.0f};    ///< Unit in-plane axes, axis_u x axis_v = normal.
  glm::vec3 axis_v{0.0f, 1.0f, 0.0f};
  glm::vec3 origin{0.0f};  ///< A point of the chart (keeps projections precise).
  glm::vec2 min_m{0.0f};   ///< Bounding rectangle of the projection, metres.
  glm::vec2 size_m{0.0f};  ///< Its size, metres; size_m.x >= size_m.y when rotated.
  double area_m2 = 0.0;    ///< World-space area of its triangles.

  /// Projection of a world point into the chart's rectangle, metres from its min corner.
  glm::vec2 project_m(glm::vec3 p) const {
    const glm::vec3 d = p - origin;
    return glm::vec2(glm::dot(d, axis_u), glm::dot(d, axis_v)) - min_m;
  }
};

/// A triangle is degenerate when |cross(b-a, c-a)| <= this x (longest edge)^2 (or not finite).
inline constexpr float kDegenerateRelativeArea = 1e-7f;

/// Charts of `mesh` (which must pass validate_atlas_inputs), in the order of their seed
/// triangles. Seeds are the lowest-index unassigned non-degenerate triangles; charts grow
/// breadth-first over shared (welded) edges. Degenerate triangles join the chart of a
/// triangle that shares a welded vertex with them (lowest triangle index first), or get a
/// chart of their own. Every triangle is in exactly one chart.
std::vector<Chart> build_charts(const AtlasInputMesh& mesh, std::uint32_t mesh_index, const ChartingSettings& settings);

}  // namespace gi
