#pragma once
// The form factor from a point to a planar convex polygon (Lambert's formula, as in Baum,
// Rushmeier and Winget 1989): the cosine-weighted solid angle of the polygon seen from point
// p with unit normal n, over pi. The part of the polygon below p's tangent plane is clipped
// away first, so the result is in [0, 1] for any placement. No visibility: what lies between
// p and the polygon is the caller's (e.g. a ray per sample).
//   const glm::vec3 tri[3] = {a, b, c};
//   float f = gi::polygon_form_factor(p, n, tri);   // share of p's cosine-weighted hemisphere

#include <span>

#include <glm/glm.hpp>

namespace gi {

/// Form factor from point `p` (unit normal `n`) to the convex planar `polygon` (3 to 8
/// corners, either winding), clipped to the half-space in front of p. 0 for fewer than 3
/// corners in front, or more than 8 corners.
float polygon_form_factor(const glm::vec3& p, const glm::vec3& n, std::span<const glm::vec3> polygon);

}  // namespace gi
