#pragma once
// Fills gi's plain ray-tracing data from a BakeInput (gi/bake_input.h).
//  - rt_scene_from: one geometry per mesh (its primitives concatenated), one instance per
//    BakeInstance, in order; Dynamic instances become dynamic ray-caster instances.
//  - reference_scene_from: the same geometry plus normals, materials (glTF's BRDF, the
//    default material for primitives without one) and the lights, for the reference path
//    tracer. A snapshot: it does not follow later changes.
//   gi::RtSceneData data = gi::rt_scene_from(input);
//   gi::ReferenceScene ref = gi::reference_scene_from(input);

#include <engine/components.h>
#include <gi/bake_input.h>

#include "raytrace/reference_scene.h"
#include "raytrace/rt_scene_data.h"

namespace gi {

RtSceneData rt_scene_from(const BakeInput& input);

ReferenceScene reference_scene_from(const BakeInput& input);

/// A light component placed by `world` as the path tracer (and the bakers) see it.
ReferenceLight reference_light(const engine::Light& light, const glm::mat4& world);

/// A material's factors as a path-tracer material (glTF's BRDF).
ReferenceMaterial reference_material(const BakeMaterial& material);

/// What the material lookup (material_lookup.h) needs of `input` without its geometry: the
/// materials as reference_scene_from makes them (index input.materials.size(): the default)
/// and their textures' mip chains. For bakers that walk BakeInput's primitives themselves.
ReferenceScene material_scene_from(const BakeInput& input);

/// Triangle t (its three indices at prim.indices[3t]) of `prim` drawn by `instance` with
/// world corners `world`, as a ShadingTriangle of material_scene_from(input): material,
/// corners, area and UVs (for the lookups; no normals, no emitter).
ShadingTriangle lookup_triangle(const BakeInput& input, const BakeInstance& instance, const BakePrimitive& prim,
                                std::size_t t, const glm::vec3 world[3]);

}  // namespace gi
