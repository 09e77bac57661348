#pragma once
// Fills gi's plain ray-tracing data from a live engine scene. The only place gi's ray
// tracing reads the registry.
//  - rt_scene_from: one geometry per mesh (its primitives concatenated), one instance per
//    MeshRenderer entity with a WorldTransform; DynamicTag entities become dynamic instances.
//  - reference_scene_from: the same geometry plus normals, materials (the renderer's rule,
//    engine::Material defaults for primitives without one) and the enabled lights, for the
//    reference path tracer. A snapshot: it does not follow later changes.
//   gi::RtSceneData data = gi::rt_scene_from(scene);
//   gi::ReferenceScene ref = gi::reference_scene_from(scene);

#include <engine/scene.h>

#include "raytrace/reference_scene.h"
#include "raytrace/rt_scene_data.h"

namespace gi {

RtSceneData rt_scene_from(const engine::Scene& scene);

ReferenceScene reference_scene_from(const engine::Scene& scene);

/// A light component placed by `world` as the path tracer (and the bakers) see it.
ReferenceLight reference_light(const engine::Light& light, const glm::mat4& world);

/// The renderer's material rule as a path-tracer material.
ReferenceMaterial reference_material(const engine::Material& material);

}  // namespace gi
