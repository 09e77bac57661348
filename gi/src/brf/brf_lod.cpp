#include "brf/brf_lod.h"

#include <algorithm>
#include <cmath>

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

}  // namespace

BrfLodPoints brf_lod_points(const BrfMesh& mesh) {
  const std::size_t nv = mesh.positions.size();
  BrfLodPoints lod;
  // Groups of (nearly) one plane, in vertex order.
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
      if (3 * groups.size() > nv / 2) return lod;  // too many groups: no table
    }
    groups[g].push_back(static_cast<std::uint32_t>(j));
  }
  // First as vertex indices (rep_of), then renumbered into `points`.
  lod.from.assign(nv, glm::uvec3(0));
  lod.weights.assign(nv, glm::vec3(0.0f));
  std::vector<std::uint8_t> is_point(nv, 0);
  const auto& pos = mesh.positions;
  for (const std::vector<std::uint32_t>& members : groups) {
    if (members.size() <= 3) {
      for (std::uint32_t m : members) {
        lod.points.push_back(m);
        lod.from[m] = glm::uvec3(m);
        lod.weights[m] = glm::vec3(1.0f, 0.0f, 0.0f);
        is_point[m] = 1;
      }
      continue;
    }
    glm::vec3 centroid(0.0f);
    for (std::uint32_t m : members) centroid += pos[m];
    centroid /= static_cast<float>(members.size());
    const std::uint32_t a = farthest(members, pos, centroid);
    const std::uint32_t b = farthest(members, pos, pos[a]);
    const glm::vec3 e0 = pos[b] - pos[a];
    const float d00 = glm::dot(e0, e0);
    // The member farthest from the line a-b.
    std::uint32_t c = a;
    float best = -1.0f;
    for (std::uint32_t m : members) {
      const glm::vec3 d = pos[m] - pos[a];
      const float t = d00 > 0.0f ? glm::dot(d, e0) / d00 : 0.0f;
      const glm::vec3 off = d - t * e0;
      const float o2 = glm::dot(off, off);
      if (o2 > best) {
        best = o2;
        c = m;
      }
    }
    const glm::vec3 e1 = pos[c] - pos[a];
    const float d01 = glm::dot(e0, e1), d11 = glm::dot(e1, e1);
    const float denom = d00 * d11 - d01 * d01;
    const bool plane = denom > 1e-6f * d00 * d11 && c != a && c != b;
    const std::uint32_t reps[3] = {a, b, plane ? c : a};
    for (std::uint32_t r : reps) {
      if (is_point[r] != 0) continue;
      lod.points.push_back(r);
      is_point[r] = 1;
    }
    for (std::uint32_t m : members) {
      lod.from[m] = glm::uvec3(reps[0], reps[1], reps[2]);
      if (is_point[m] != 0) {
        lod.from[m] = glm::uvec3(m);
        lod.weights[m] = glm::vec3(1.0f, 0.0f, 0.0f);
        continue;
      }
      const glm::vec3 d = pos[m] - pos[a];
      const float d20 = glm::dot(d, e0), d21 = glm::dot(d, e1);
      if (plane) {
        const float v = (d11 * d20 - d01 * d21) / denom, w = (d00 * d21 - d01 * d20) / denom;
        lod.weights[m] = glm::vec3(1.0f - v - w, v, w);
      } else {
        const float t = d00 > 0.0f ? d20 / d00 : 0.0f;
        lod.weights[m] = glm::vec3(1.0f - t, t, 0.0f);
      }
    }
  }
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

}  // namespace gi
