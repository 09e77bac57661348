#include "brf/brf_lod.h"
#include "brf/brf_runtime.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gi {

namespace {

/// The member of `members` farthest from p (first on ties).
std::uint32_t farthest(std::span<const std::uint32_t> members, const std::vector<glm::vec3>& positions,
                       const glm::vec3& p) {
  std::uint32_t best = members[0];
  float best_d = -1.0f;
  for (std::uint32_t m : members) {
    const glm::vec3 d = positions[m] - p;
    const float d2 = glm::dot(d, d);
    if (d2 > best_d) {
      best_d = d2;
      best = m;
    }
  }
  return best;
}

/// Vertices of (nearly) one plane, in vertex order: a group per plane (normals within
/// kBrfLodNormalCos, points within the tolerance of the first member's plane). Empty when there
/// would be too many groups for a table to pay (3 x groups > V / 2).
std::vector<std::vector<std::uint32_t>> plane_groups(const BrfMesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  glm::vec3 lo(0.0f), hi(0.0f);
  for (std::size_t j = 0; j < nv; ++j) {
    lo = j == 0 ? mesh.positions[j] : glm::min(lo, mesh.positions[j]);
    hi = j == 0 ? mesh.positions[j] : glm::max(hi, mesh.positions[j]);
  }
  const float plane_tolerance = kBrfLodPlaneTolerance * 0.5f * glm::length(hi - lo);
  std::vector<std::vector<std::uint32_t>> groups;
  std::vector<glm::vec3> group_normal, group_point;
  for (std::size_t j = 0; j < nv; ++j) {
    std::size_t g = 0;
    while (g < groups.size() &&
           (glm::dot(group_normal[g], mesh.normals[j]) < kBrfLodNormalCos ||
            std::fabs(glm::dot(group_normal[g], mesh.positions[j] - group_point[g])) > plane_tolerance))
      ++g;
    if (g == groups.size()) {
      groups.emplace_back();
      group_normal.push_back(mesh.normals[j]);
      group_point.push_back(mesh.positions[j]);
      if (3 * groups.size() > nv / 2) return {};  // too many groups: no table
    }
    groups[g].push_back(static_cast<std::uint32_t>(j));
  }
  return groups;
}

/// A group's extreme members and in-plane axes: a farthest from the centroid, b farthest
/// from a, c farthest from the line a-b; `plane` when a, b, c span a triangle. The axes run
/// along a-c (a rectangle's edge: a and b are opposite corners) and across it.
struct GroupFrame {
  std::uint32_t a = 0, b = 0, c = 0;
  glm::vec3 e0{0.0f};  ///< b - a
  float d00 = 0.0f;    ///< |e0|^2
  bool plane = false;
  glm::vec3 eu{0.0f}, ev{0.0f};
  /// Member m's coordinates in the group's plane.
  glm::vec2 uv(const std::vector<glm::vec3>& pos, std::uint32_t m) const {
    return glm::vec2(glm::dot(pos[m] - pos[a], eu), glm::dot(pos[m] - pos[a], ev));
  }
};

GroupFrame group_frame(const std::vector<std::uint32_t>& members, const std::vector<glm::vec3>& pos) {
  GroupFrame f;
  glm::vec3 centroid(0.0f);
  for (std::uint32_t m : members) centroid += pos[m];
  centroid /= static_cast<float>(members.size());
  f.a = farthest(members, pos, centroid);
  f.b = farthest(members, pos, pos[f.a]);
  f.e0 = pos[f.b] - pos[f.a];
  f.d00 = glm::dot(f.e0, f.e0);
  // The member farthest from the line a-b.
  f.c = f.a;
  float best = -1.0f;
  for (std::uint32_t m : members) {
    const glm::vec3 d = pos[m] - pos[f.a];
    const float t = f.d00 > 0.0f ? glm::dot(d, f.e0) / f.d00 : 0.0f;
    const glm::vec3 off = d - t * f.e0;
    const float o2 = glm::dot(off, off);
    if (o2 > best) {
      best = o2;
      f.c = m;
    }
  }
  const glm::vec3 e1 = pos[f.c] - pos[f.a];
  const float d01 = glm::dot(f.e0, e1), d11 = glm::dot(e1, e1);
  const float denom = f.d00 * d11 - d01 * d01;
  f.plane = denom > 1e-6f * f.d00 * d11 && f.c != f.a && f.c != f.b;
  f.eu = f.plane ? glm::normalize(e1) : f.e0;
  f.ev = f.plane ? glm::normalize(f.e0 - glm::dot(f.e0, f.eu) * f.eu) : f.e0;
  return f;
}

/// A group's representative points: in its plane, a lattice of G x G nodes over its extent
/// [lo2, hi2], each taken by the member nearest to it (G = 3 for groups of 64 members or
/// more, 2 from 8), else the triangle a b c (the line a b off a plane).
std::vector<std::uint32_t> lattice_points(const std::vector<std::uint32_t>& members, const std::vector<glm::vec3>& pos,
                                          const GroupFrame& f, glm::vec2 lo2, glm::vec2 hi2) {
  std::vector<std::uint32_t> reps;
  const int lattice = !f.plane ? 0 : members.size() >= 64 ? 3 : members.size() >= 8 ? 2 : 0;
  for (int i = 0; i < lattice; ++i)
    for (int k = 0; k < lattice; ++k) {
      const glm::vec2 node =
          lo2 + (hi2 - lo2) * glm::vec2(static_cast<float>(i), static_cast<float>(k)) / static_cast<float>(lattice - 1);
      std::uint32_t best_m = members[0];
      float best_d = std::numeric_limits<float>::max();
      for (std::uint32_t m : members) {
        const glm::vec2 d = f.uv(pos, m) - node;
        if (glm::dot(d, d) < best_d) {
          best_d = glm::dot(d, d);
          best_m = m;
        }
      }
      if (std::find(reps.begin(), reps.end(), best_m) == reps.end()) reps.push_back(best_m);
    }
  if (reps.size() < 3)
    reps = f.plane ? std::vector<std::uint32_t>{f.a, f.b, f.c} : std::vector<std::uint32_t>{f.a, f.b};
  return reps;
}

/// Member m's entry in `lod` (vertex indices): from the smallest triangle of representative
/// points holding it (barycentric weights >= 0), else the one it lies least outside of.
void triangle_weights(std::uint32_t m, const std::vector<std::uint32_t>& reps, const std::vector<glm::vec3>& pos,
                      const GroupFrame& f, float area, BrfLodPoints& lod) {
  const glm::vec2 x = f.uv(pos, m);
  float best_area = std::numeric_limits<float>::max(), best_outside = -std::numeric_limits<float>::max();
  bool inside_found = false;
  for (std::size_t i = 0; i < reps.size(); ++i)
    for (std::size_t j = i + 1; j < reps.size(); ++j)
      for (std::size_t k = j + 1; k < reps.size(); ++k) {
        const glm::vec2 p0 = f.uv(pos, reps[i]), p1 = f.uv(pos, reps[j]), p2 = f.uv(pos, reps[k]);
        const float det = (p1.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (p1.y - p0.y);
        if (std::fabs(det) <= 1e-4f * area) continue;
        const float w1 = ((x.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (x.y - p0.y)) / det;
        const float w2 = ((p1.x - p0.x) * (x.y - p0.y) - (x.x - p0.x) * (p1.y - p0.y)) / det;
        const glm::vec3 w(1.0f - w1 - w2, w1, w2);
        const float least = std::min({w.x, w.y, w.z});
        const bool inside = least >= -1e-5f;
        if (inside ? (!inside_found || std::fabs(det) < best_area) : (!inside_found && least > best_outside)) {
          inside_found = inside_found || inside;
          best_area = std::fabs(det);
          best_outside = least;
          lod.from[m] = glm::uvec3(reps[i], reps[j], reps[k]);
          lod.weights[m] = w;
        }
      }
}

/// One group's representative points into `lod` (vertex indices) and every member's entry.
void add_group(const std::vector<std::uint32_t>& members, const std::vector<glm::vec3>& pos, BrfLodPoints& lod,
               std::vector<std::uint8_t>& is_point) {
  if (members.size() <= 3) {
    for (std::uint32_t m : members) {
      lod.points.push_back(m);
      lod.from[m] = glm::uvec3(m);
      lod.weights[m] = glm::vec3(1.0f, 0.0f, 0.0f);
      is_point[m] = 1;
    }
    return;
  }
  const GroupFrame f = group_frame(members, pos);
  glm::vec2 lo2(0.0f), hi2(0.0f);
  for (std::uint32_t m : members) {
    lo2 = glm::min(lo2, f.uv(pos, m));
    hi2 = glm::max(hi2, f.uv(pos, m));
  }
  const std::vector<std::uint32_t> reps = lattice_points(members, pos, f, lo2, hi2);
  for (std::uint32_t r : reps) {
    lod.points.push_back(r);
    is_point[r] = 1;
  }
  const float area = std::max((hi2.x - lo2.x) * (hi2.y - lo2.y), 1e-12f);
  for (std::uint32_t m : members) {
    if (is_point[m] != 0) {
      lod.from[m] = glm::uvec3(m);
      lod.weights[m] = glm::vec3(1.0f, 0.0f, 0.0f);
    } else if (reps.size() == 2) {  // a line
      const float t = f.d00 > 0.0f ? glm::dot(pos[m] - pos[f.a], f.e0) / f.d00 : 0.0f;
      lod.from[m] = glm::uvec3(reps[0], reps[1], reps[0]);
      lod.weights[m] = glm::vec3(1.0f - t, t, 0.0f);
    } else {
      triangle_weights(m, reps, pos, f, area, lod);
    }
  }
}

}  // namespace

BrfLodPoints brf_lod_points(const BrfMesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  BrfLodPoints lod;
  const std::vector<std::vector<std::uint32_t>> groups = plane_groups(mesh);
  if (groups.empty()) return lod;
  // First as vertex indices, then renumbered into `points`.
  lod.from.assign(nv, glm::uvec3(0));
  lod.weights.assign(nv, glm::vec3(0.0f));
  std::vector<std::uint8_t> is_point(nv, 0);
  for (const std::vector<std::uint32_t>& members : groups) add_group(members, mesh.positions, lod, is_point);
  std::sort(lod.points.begin(), lod.points.end());
  if (2 * lod.points.size() > nv) return BrfLodPoints{};
  std::vector<std::uint32_t> index(nv, 0);  // vertex -> position in points
  for (std::size_t i = 0; i < lod.points.size(); ++i) index[lod.points[i]] = static_cast<std::uint32_t>(i);
  for (glm::uvec3& f : lod.from) f = glm::uvec3(index[f.x], index[f.y], index[f.z]);
  return lod;
}

bool brf_pair_far(const BrfSphere& receiver, const BrfSphere& source_inner, float lod_distance) {
  if (!(lod_distance > 0.0f) || !std::isfinite(lod_distance)) return false;
  return glm::length(receiver.centre - source_inner.centre) - receiver.radius >= lod_distance * source_inner.radius;
}

void brf_lod_interpolate(const BrfLodPoints& lod, std::size_t j, std::span<const float> rows, std::size_t row_floats,
                         float scale, float* out) {
  const float* a = rows.data() + lod.from[j].x * row_floats;
  const float* b = rows.data() + lod.from[j].y * row_floats;
  const float* c = rows.data() + lod.from[j].z * row_floats;
  const glm::vec3 w = lod.weights[j];
  for (std::size_t k = 0; k < row_floats; ++k) out[k] = ((w.x * a[k] + w.y * b[k]) + w.z * c[k]) * scale;
}

BrfVertexError brf_vertex_error(const BrfResult& approx, const BrfResult& exact) {
  double mean = 0.0;
  std::size_t count = 0;
  for (const auto& v : exact.indirect)
    for (const glm::vec3& e : v) {
      mean += glm::length(glm::dvec3(e));
      ++count;
    }
  mean /= static_cast<double>(std::max<std::size_t>(count, 1));
  std::vector<double> rel;
  rel.reserve(count);
  for (std::size_t o = 0; o < exact.indirect.size(); ++o)
    for (std::size_t j = 0; j < exact.indirect[o].size(); ++j) {
      const double d = glm::length(glm::dvec3(approx.indirect[o][j]) - glm::dvec3(exact.indirect[o][j]));
      rel.push_back(d / std::max(glm::length(glm::dvec3(exact.indirect[o][j])), 0.01 * mean));
    }
  if (rel.empty()) return {};
  std::sort(rel.begin(), rel.end());
  return {rel.back(), rel[static_cast<std::size_t>(0.95 * static_cast<double>(rel.size() - 1))]};
}

}  // namespace gi
