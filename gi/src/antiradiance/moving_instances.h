#pragma once
// The deforming instances of a region and where they have swept since the last look: what the
// direct light at the leaves (antiradiance_direct_light.h) and the diagnosis solver with exact
// visibility (antiradiance_exact_transport.h) both need to recompute only what a door move can
// change.
//   RtSceneData data = gi::rt_scene_from(input);
//   gi::MovingInstances moving = gi::MovingInstances::mark(input, data);  // dynamic in data
//   moving.move(door, m);  for (const auto& box : moving.swept()) ...;  moving.clear_swept();

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <gi/bake_input.h>

#include "raytrace/scene_adapter.h"

namespace gi {

class MovingInstances {
 public:
  struct Box {
    glm::vec3 lo, hi;
  };

  /// The instances of `input` flagged deforming, their object-space bounds and current
  /// transforms; marks them dynamic in `data` (the ray caster's scene built from `input`).
  static MovingInstances mark(const BakeInput& input, RtSceneData& data);

  /// True for a BakeInput index flagged deforming (false for -1, static or out of range).
  bool deforming(std::int32_t instance) const {
    return instance >= 0 && static_cast<std::size_t>(instance) < deforming_.size() &&
           deforming_[static_cast<std::size_t>(instance)] != 0;
  }
  /// Records the move of deforming instance `instance` to `object_to_world`: its world bounds
  /// before and after (1 cm margin) join swept(). Precondition: deforming(instance).
  void move(std::uint32_t instance, const glm::mat4& object_to_world);
  /// The world boxes the moved instances occupied before and after their moves since the last
  /// clear_swept().
  const std::vector<Box>& swept() const { return swept_; }
  void clear_swept() { swept_.clear(); }

 private:
  Box world_bounds(std::uint32_t instance, const glm::mat4& m) const;

  std::vector<char> deforming_;
  std::vector<Box> object_bounds_;    ///< Per BakeInput instance (deforming ones only meaningful).
  std::vector<glm::mat4> transform_;  ///< Per BakeInput instance: its current transform.
  std::vector<Box> swept_;
};

}  // namespace gi
