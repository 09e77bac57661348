#pragma once
// Plain triangle data for the ray casters: geometries in object space and instances that
// place them in the world. Bakers fill it through the adapter (scene_adapter.h), never from
// the registry directly.

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

struct RtGeometry {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;  ///< 3 per triangle.
};

struct RtInstance {
  std::uint32_t geometry = 0;
  glm::mat4 object_to_world{1.0f};
  /// Dynamic instances may get a new transform every frame (set_instance_transform).
  bool dynamic = false;
  /// Caller's id for the instance (e.g. the engine entity id); not used by the casters.
  std::uint64_t user_id = 0;
};

struct RtSceneData {
  std::vector<RtGeometry> geometries;
  std::vector<RtInstance> instances;
};

}  // namespace gi
