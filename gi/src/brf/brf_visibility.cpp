#include "brf/brf_visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "raytrace/ray_caster.h"
#include "raytrace/ray_offset.h"

namespace gi {

std::array<glm::vec3, kBrfVisibilityTargets> brf_visibility_targets(const BrfBox& box) {
  const glm::vec3 c = 0.5f * (box.lo + box.hi), h = kBrfCornerPull * 0.5f * (box.hi - box.lo);
  std::array<glm::vec3, kBrfVisibilityTargets> t{};
  t[0] = c;
  for (int k = 0; k < 8; ++k)
    t[static_cast<std::size_t>(k) + 1] =
        c + glm::vec3((k & 1) != 0 ? h.x : -h.x, (k & 2) != 0 ? h.y : -h.y, (k & 4) != 0 ? h.z : -h.z);
  return t;
}

void brf_static_visibility(const RayCaster& world, std::span<const glm::vec3> targets,
                           std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                           std::span<float> out) {
  // All rays of all receivers in one stream, then the weighted fractions per receiver.
  std::vector<Ray> rays;
  rays.reserve(positions.size() * targets.size());
  for (std::size_t j = 0; j < positions.size(); ++j) {
    const glm::vec3 o = offset_ray_origin(positions[j], normals[j]);
    brf_weighted_visibility(positions[j], normals[j], targets, [&](std::size_t, const glm::vec3&, const glm::vec3& t) {
      rays.push_back(Ray{o, 0.0f, t - o, 1.0f});
      return false;
    });
  }
  std::vector<std::uint8_t> blocked(rays.size(), 0);
  world.occluded_many(rays, blocked);
  std::size_t next = 0;
  for (std::size_t j = 0; j < positions.size(); ++j)
    out[j] =
        brf_weighted_visibility(positions[j], normals[j], targets,
                                [&](std::size_t, const glm::vec3&, const glm::vec3&) { return blocked[next++] == 0; });
}

float brf_box_form_factor(const BrfBox& box, const glm::mat4& object_to_world, const glm::vec3& p, const glm::vec3& n) {
  const glm::vec3 local = glm::vec3(glm::inverse(object_to_world) * glm::vec4(p, 1.0f));
  if (glm::all(glm::greaterThan(local, box.lo)) && glm::all(glm::lessThan(local, box.hi))) return 1.0f;
  // Faces as corner indices (bit 0: x, 1: y, 2: z high) with the axis and side they face.
  static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  std::array<glm::vec3, 8> corner;
  for (int k = 0; k < 8; ++k)
    corner[static_cast<std::size_t>(k)] =
        glm::vec3(object_to_world * glm::vec4((k & 1) != 0 ? box.hi.x : box.lo.x, (k & 2) != 0 ? box.hi.y : box.lo.y,
                                              (k & 4) != 0 ? box.hi.z : box.lo.z, 1.0f));
  float total = 0.0f;
  for (int f = 0; f < 6; ++f) {
    const int axis = f / 2;
    const bool high = (f % 2) == 1;
    // p sees the face when it lies beyond the face's plane (object space).
    if (high ? local[axis] <= box.hi[axis] : local[axis] >= box.lo[axis]) continue;
    // Lambert: sum over edges of angle x (n . edge plane normal) / 2 pi; the same sum against
    // the direction to the face's centre (wholly in front) gives the winding's sign.
    glm::vec3 centre(0.0f);
    for (int e = 0; e < 4; ++e) centre += 0.25f * corner[static_cast<std::size_t>(kFaces[f][e])];
    const glm::vec3 towards = glm::normalize(centre - p);
    float sum = 0.0f, sign = 0.0f;
    for (int e = 0; e < 4; ++e) {
      const glm::vec3 a = glm::normalize(corner[static_cast<std::size_t>(kFaces[f][e])] - p);
      const glm::vec3 b = glm::normalize(corner[static_cast<std::size_t>(kFaces[f][(e + 1) % 4])] - p);
      const glm::vec3 c = glm::cross(a, b);
      const float len = glm::length(c);
      if (!(len > 0.0f)) continue;
      const float angle = std::acos(std::clamp(glm::dot(a, b), -1.0f, 1.0f));
      sum += angle * glm::dot(n, c / len);
      sign += angle * glm::dot(towards, c / len);
    }
    // Parts of a face below p's horizon count negative in the formula: a face mostly below
    // it adds nothing.
    total += std::clamp((sign < 0.0f ? -sum : sum) / (2.0f * std::numbers::pi_v<float>), 0.0f, 1.0f);
  }
  return std::clamp(total, 0.0f, 1.0f);
}

float brf_contact_visibility(const BrfBox& box, const glm::vec3& p, const glm::vec3& n) {
  // Slab test of the ray p + t n, t >= 0 (the same arithmetic as brf_phi.comp.glsl).
  const glm::vec3 half = 0.5f * (box.hi - box.lo);
  const float gap = kBrfContactGap * (half.x + half.y + half.z) / 3.0f;
  float t0 = -std::numeric_limits<float>::infinity(), t1 = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(n[k]) < 1e-12f) {
      if (p[k] < box.lo[k] || p[k] > box.hi[k]) return 1.0f;
      continue;
    }
    const float inv = 1.0f / n[k];
    float ta = (box.lo[k] - p[k]) * inv, tb = (box.hi[k] - p[k]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1 || t1 < 0.0f) return 1.0f;  // the normal misses the box (or it lies behind)
  if (t0 <= 0.0f) return 0.0f;            // inside the box
  return t0 >= gap ? 1.0f : t0 / gap;
}

BrfSphere brf_bounding_sphere(const BrfBox& box, const glm::mat4& object_to_world) {
  const glm::vec3 c = 0.5f * (box.lo + box.hi);
  const float scale = glm::length(glm::vec3(object_to_world[0]));
  return {glm::vec3(object_to_world * glm::vec4(c, 1.0f)), scale * glm::length(0.5f * (box.hi - box.lo))};
}

std::vector<std::uint32_t> brf_pair_occluders(std::span<const BrfSphere> spheres, std::size_t source,
                                              std::size_t receiver) {
  std::vector<std::uint32_t> out;
  const glm::vec3 a = spheres[receiver].centre, b = spheres[source].centre;
  const float reach = std::max(spheres[receiver].radius, spheres[source].radius);
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  for (std::size_t o = 0; o < spheres.size(); ++o) {
    if (o == source || o == receiver) continue;
    const float t = len2 > 0.0f ? std::clamp(glm::dot(spheres[o].centre - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
    if (glm::length(spheres[o].centre - (a + t * ab)) < spheres[o].radius + reach)
      out.push_back(static_cast<std::uint32_t>(o));
  }
  return out;
}

bool brf_segment_clear(const glm::vec3& a, const glm::vec3& b, std::span<const BrfOccluder> occluders) {
  // Slab test in each occluder's object space for t in [0, 1]; the same arithmetic as
  // brf_segment_clear in brf_common.glsl.
  for (const BrfOccluder& o : occluders) {
    const glm::vec3 p = glm::vec3(o.to_occluder * glm::vec4(a, 1.0f));
    const glm::vec3 d = glm::vec3(o.to_occluder * glm::vec4(b, 1.0f)) - p;
    float t0 = 0.0f, t1 = 1.0f;
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      if (std::fabs(d[k]) < 1e-12f) {
        miss = p[k] < o.box.lo[k] || p[k] > o.box.hi[k];
        continue;
      }
      const float inv = 1.0f / d[k];
      float ta = (o.box.lo[k] - p[k]) * inv, tb = (o.box.hi[k] - p[k]) * inv;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      miss = t0 > t1;
    }
    if (!miss) return false;
  }
  return true;
}

void brf_box_visibility(std::span<const BrfOccluder> occluders, std::span<const glm::vec3> targets,
                        std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                        std::span<float> out) {
  for (std::size_t j = 0; j < positions.size(); ++j)
    out[j] = occluders.empty() ? 1.0f
                               : brf_weighted_visibility(positions[j], normals[j], targets,
                                                         [&](std::size_t, const glm::vec3& p, const glm::vec3& t) {
                                                           return brf_segment_clear(p, t, occluders);
                                                         });
}

}  // namespace gi
