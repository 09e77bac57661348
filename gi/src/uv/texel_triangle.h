#pragma once
// 2-D geometry of a triangle in atlas texel space: point containment, barycentrics, the
// closest point to a texel centre, and overlap with a texel square. Used by the atlas
// rasterizer; degenerate (zero-area) triangles are handled everywhere.
//   gi::TrianglePoint c = gi::closest_point_on_triangle(centre, a, b, c);
//   glm::vec3 world = c.barycentric.x * pa + c.barycentric.y * pb + c.barycentric.z * pc;

#include <glm/glm.hpp>

namespace gi {

/// A point of a triangle and its barycentric coordinates (weights of a, b, c; sum 1).
struct TrianglePoint {
  glm::vec2 point{0.0f};
  glm::vec3 barycentric{1.0f, 0.0f, 0.0f};
};

/// True when p is inside triangle abc or on its boundary (either winding). Edge functions are
/// evaluated in double; a degenerate triangle contains no point.
bool triangle_contains(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c);

/// Barycentric coordinates of p with respect to a non-degenerate triangle abc.
glm::vec3 triangle_barycentric(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c);

/// The point of triangle abc (a filled triangle, or the segment/point it degenerates to)
/// closest to p in the Euclidean distance, with its barycentrics.
TrianglePoint closest_point_on_triangle(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c);

/// True when triangle abc (or the segment/point it degenerates to) intersects the closed
/// square [lo, hi] grown by `eps` on each side (separating axis test).
bool triangle_overlaps_box(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 lo, glm::vec2 hi, float eps);

}  // namespace gi
