#include "raytrace/brute_force_ray_caster.h"

#include <cmath>

#include <engine/check.h>

namespace gi {

BruteForceRayCaster::BruteForceRayCaster(RtSceneData data) : data_(std::move(data)) { commit(); }

void BruteForceRayCaster::set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world) {
  GI_EXPECTS(instance < data_.instances.size(), "instance index out of range");
  data_.instances[instance].object_to_world = object_to_world;
}

void BruteForceRayCaster::commit() {
  triangles_.clear();
  for (std::uint32_t i = 0; i < data_.instances.size(); ++i) {
    const RtInstance& inst = data_.instances[i];
    const RtGeometry& geo = data_.geometries[inst.geometry];
    for (std::uint32_t t = 0; t < geo.indices.size() / 3; ++t) {
      auto world = [&](std::uint32_t k) {
        return glm::vec3(inst.object_to_world * glm::vec4(geo.positions[geo.indices[3 * t + k]], 1.0f));
      };
      const glm::vec3 p0 = world(0);
      triangles_.push_back(Triangle{p0, world(1) - p0, world(2) - p0, i, inst.geometry, t});
    }
  }
}

Hit BruteForceRayCaster::intersect(const Ray& ray) const {
  Hit best;
  best.t = ray.t_max;
  for (const Triangle& tri : triangles_) {
    const glm::vec3 pv = glm::cross(ray.direction, tri.e2);
    const float det = glm::dot(tri.e1, pv);
    if (std::abs(det) < 1e-20f) continue;
    const float inv = 1.0f / det;
    const glm::vec3 tv = ray.origin - tri.p0;
    const float u = glm::dot(tv, pv) * inv;
    if (u < 0.0f || u > 1.0f) continue;
    const glm::vec3 qv = glm::cross(tv, tri.e1);
    const float v = glm::dot(ray.direction, qv) * inv;
    if (v < 0.0f || u + v > 1.0f) continue;
    const float t = glm::dot(tri.e2, qv) * inv;
    if (t < ray.t_min || t > best.t) continue;
    const RtGeometry& geo = data_.geometries[tri.geometry];
    if (geo.cutout && geo.cutout->cut(geo.indices, tri.primitive, {u, v})) continue;  // alpha cut-out
    best.t = t;
    best.instance = tri.instance;
    best.geometry = tri.geometry;
    best.primitive = tri.primitive;
    best.barycentric = {u, v};
    best.geometric_normal = glm::cross(tri.e1, tri.e2);
  }
  if (!best.valid()) best.t = std::numeric_limits<float>::infinity();
  return best;
}

bool BruteForceRayCaster::occluded(const Ray& ray) const { return intersect(ray).valid(); }

}  // namespace gi
