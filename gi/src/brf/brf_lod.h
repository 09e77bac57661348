#pragma once
// Level of detail for distant (source, receiver) pairs (docs/brf.md "Level of detail"). Far
// from a source (beyond BrfUpdateSettings::lod_distance x its innermost field sphere) its
// field varies slowly over a receiver, so the field part of the pair's basis irradiance Phi
// (the field sampled at the vertex, dotted with its cosine lobe) is evaluated only at a few
// representative vertices of the receiver and interpolated to the others with fixed weights
// chosen once per mesh. What is not smooth stays per vertex: which side of the vertex's
// tangent plane the source lies on (brf_horizon) and how much of it the vertex sees
// (contact and occluders, brf_visibility.h), which scales the interpolated row.
//   - the vertices are grouped by plane (greedy: normal cos >= kBrfLodNormalCos to the group's
//     first vertex's, and within kBrfLodPlaneTolerance x the mesh's bounding radius of its
//     plane): the lobe is then the same over a group and the source on the same side of it;
//   - per group, representative vertices on a lattice over its extent in its plane (the member
//     nearest to each of 3 x 3 nodes for groups of 64 members or more, 2 x 2 from 8; else 3
//     spanning it: farthest from the centroid, farthest from that, farthest from the line
//     through both; 2 when the group is a line, all of it when it has at most 3); every other
//     vertex takes the barycentric coordinates of the smallest triangle of them holding it
//     (exact for a field part linear over the triangle; no extrapolation inside the lattice).
//     A crate face of 5 x 5 vertices: its 4 corners, 24 points for the crate of 150 vertices.
// A mesh of smooth normals (many groups) gets no table (points empty): its pairs stay exact.
// Only diffuse receivers (one Phi row per vertex) use it; glossy receivers are evaluated in full.
//   gi::BrfLodPoints lod = gi::brf_lod_points(mesh);
//   if (gi::brf_pair_far(receiver_sphere, source_inner_sphere, settings.lod_distance)) ...

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "brf/brf_visibility.h"
#include "brf/pca_basis.h"

namespace gi {

inline constexpr float kBrfLodNormalCos = 0.98f;       ///< Normals within ~11 degrees share a group.
inline constexpr float kBrfLodPlaneTolerance = 0.01f;  ///< Plane offset, x the bounding radius.

struct BrfLodPoints {
  /// The representative vertices, ascending. Empty: no table (every vertex is evaluated).
  std::vector<std::uint32_t> points;
  /// Per vertex: the three representative points it is interpolated from (indices into
  /// `points`) and their weights (a representative vertex: itself three times, weights
  /// (1, 0, 0); unused entries weight 0).
  std::vector<glm::uvec3> from;
  std::vector<glm::vec3> weights;

  bool empty() const { return points.empty(); }
};

/// The table of `mesh` (deterministic). Empty when the representative vertices would be more
/// than half of the vertices (smooth meshes, tiny meshes).
BrfLodPoints brf_lod_points(const BrfMesh& mesh);

/// A pair is far when the receiver's bounding sphere (world space) lies at least
/// lod_distance x the source's innermost field sphere radius from the source's field centre
/// (`source_inner`: that sphere in world space), i.e. |c_r - c_s| - r_r >= lod_distance x r_s.
/// lod_distance <= 0 or not finite: never (the exact evaluation everywhere).
bool brf_pair_far(const BrfSphere& receiver, const BrfSphere& source_inner, float lod_distance);

/// Vertex j's row from the representative points' rows (`rows`: one row of `row_floats`
/// floats per point, in `points` order): out[c] = scale x ((w0 a[c] + w1 b[c]) + w2 c[c]).
void brf_lod_interpolate(const BrfLodPoints& lod, std::size_t j, std::span<const float> rows, std::size_t row_floats,
                         float scale, float* out);

}  // namespace gi
