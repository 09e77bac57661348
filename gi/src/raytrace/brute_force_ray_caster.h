#pragma once
// A RayCaster that tests every triangle (Möller-Trumbore): slow, obviously correct, the
// ground truth the Embree caster is tested against.
//   gi::BruteForceRayCaster rc(data);

#include <vector>

#include "raytrace/ray_caster.h"
#include "raytrace/rt_scene_data.h"

namespace gi {

class BruteForceRayCaster final : public RayCaster {
 public:
  explicit BruteForceRayCaster(RtSceneData data);

  Hit intersect(const Ray& ray) const override;
  bool occluded(const Ray& ray) const override;
  void set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world) override;
  void commit() override;

 private:
  struct Triangle {
    glm::vec3 p0, e1, e2;
    std::uint32_t instance, geometry, primitive;
  };
  RtSceneData data_;
  std::vector<Triangle> triangles_;
};

}  // namespace gi
