#pragma once
// Fills the ray casters' plain data from a live engine scene: one geometry per mesh (its
// primitives concatenated), one instance per MeshRenderer entity with a WorldTransform.
// Entities with DynamicTag become dynamic instances. The only place gi's ray tracing reads
// the registry.
//   gi::RtSceneData data = gi::rt_scene_from(scene);

#include <engine/scene.h>

#include "raytrace/rt_scene_data.h"

namespace gi {

RtSceneData rt_scene_from(const engine::Scene& scene);

}  // namespace gi
