#pragma once
// The ray-casting interface the bakers and the reference renderer use. Embree implements it
// (embree_ray_caster.h); a brute-force implementation serves tests as the ground truth.
//   std::unique_ptr<gi::RayCaster> rc = gi::make_embree_ray_caster(data).value();
//   gi::Hit h = rc->intersect(gi::Ray{.origin = p, .direction = d});

#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include "raytrace/ray.h"

namespace gi {

class RayCaster {
 public:
  virtual ~RayCaster() = default;
  /// Closest hit along the ray within [t_min, t_max], or an invalid Hit.
  virtual Hit intersect(const Ray& ray) const = 0;
  /// intersect() whose Hit::geometric_normal may be left 0 (the rest is the same): for callers
  /// that take the normal from their own tables, spared its cache miss.
  virtual Hit intersect_without_normal(const Ray& ray) const { return intersect(ray); }
  /// True when anything lies along the ray within [t_min, t_max].
  virtual bool occluded(const Ray& ray) const = 0;
  /// Closest hits of many rays (a stream; implementations may batch). hits.size() == rays.size().
  virtual void intersect_many(std::span<const Ray> rays, std::span<Hit> hits) const;
  /// Occlusion of many rays; out[i] = occluded(rays[i]).
  virtual void occluded_many(std::span<const Ray> rays, std::span<std::uint8_t> out) const;
  /// occluded_many for rays that run close together (e.g. shadow rays towards one light):
  /// implementations may trace them in packets. out[i] = occluded(rays[i]), the same answers.
  virtual void occluded_coherent(std::span<const Ray> rays, std::span<std::uint8_t> out) const;
  /// Moves a dynamic instance; takes effect at the next commit().
  virtual void set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world) = 0;
  /// Rebuilds what changed since the last commit (only the top level for moved instances).
  virtual void commit() = 0;
};

}  // namespace gi
