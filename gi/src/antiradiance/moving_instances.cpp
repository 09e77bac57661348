#include "antiradiance/moving_instances.h"

#include <engine/check.h>

#include <limits>

namespace gi {

MovingInstances MovingInstances::mark(const BakeInput& input, RtSceneData& data) {
  MovingInstances out;
  const std::size_t n = input.instances.size();
  out.deforming_.assign(n, 0);
  out.object_bounds_.assign(n, Box{glm::vec3(0.0f), glm::vec3(0.0f)});
  out.transform_.assign(n, glm::mat4(1.0f));
  for (std::size_t i = 0; i < n; ++i) {
    out.transform_[i] = input.instances[i].object_to_world;
    if (!input.instances[i].deforming) continue;
    if (i < data.instances.size()) data.instances[i].dynamic = true;
    out.deforming_[i] = 1;
    Box b{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
    for (const BakePrimitive& p : input.meshes[input.instances[i].mesh].primitives)
      for (const glm::vec3& v : p.positions) {
        b.lo = glm::min(b.lo, v);
        b.hi = glm::max(b.hi, v);
      }
    out.object_bounds_[i] = b;
  }
  return out;
}

MovingInstances::Box MovingInstances::world_bounds(std::uint32_t instance, const glm::mat4& m) const {
  const Box& o = object_bounds_[instance];
  Box w{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
  if (!(o.lo.x <= o.hi.x)) return w;  // an empty mesh
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? o.hi.x : o.lo.x, (c & 2) ? o.hi.y : o.lo.y, (c & 4) ? o.hi.z : o.lo.z);
    const glm::vec3 p(m * glm::vec4(corner, 1.0f));
    w.lo = glm::min(w.lo, p);
    w.hi = glm::max(w.hi, p);
  }
  const glm::vec3 margin(0.01f);
  w.lo -= margin;
  w.hi += margin;
  return w;
}

void MovingInstances::move(std::uint32_t instance, const glm::mat4& object_to_world) {
  GI_EXPECTS(deforming(static_cast<std::int32_t>(instance)), "MovingInstances: only deforming instances move");
  swept_.push_back(world_bounds(instance, transform_[instance]));
  swept_.push_back(world_bounds(instance, object_to_world));
  transform_[instance] = object_to_world;
}

}  // namespace gi
