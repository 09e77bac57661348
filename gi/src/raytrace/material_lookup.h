#pragma once
// The one material lookup of every baker and the path tracer (docs/materials-in-bakes.md):
// the glTF material at a point of a triangle, its textures read at the point's material UV
// for a footprint. Base colour = factor x texture (sRGB-decoded), roughness = factor x G,
// metallic = factor x B of the metallic-roughness texture, emission = factor x emissive
// texture (sRGB-decoded). A material without textures costs nothing more than before.
//
// Footprints: a lookup for a ray takes the world-space width of the ray's footprint at the
// hit (ray cone: distance x spread, path_tracer.h) and reads the mip level whose texel spans
// it (footprint x the triangle's UV units per metre). A receiving surface element (a light-
// atlas texel, a BRF vertex, an antiradiance element) folds in the texture's mean over its
// footprint: 4 x 4 stratified points over it, each read at the level of its share.
//   engine::GltfBrdf b = gi::material_brdf_at(scene, tri, bary, footprint_m);
//   glm::vec3 rho = gi::footprint_albedo(scene, tri, centre, axis_u, axis_v);

#include <engine/gltf_brdf.h>

#include <glm/glm.hpp>

#include "raytrace/reference_scene.h"

namespace gi {

/// glTF's BRDF at barycentrics `bary` of `tri` for a footprint `footprint_m` metres wide
/// (0: the finest level).
engine::GltfBrdf material_brdf_at(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 bary,
                                  float footprint_m);

/// Emitted radiance (W/(m^2 sr)) at `bary` of `tri`: emission x the emissive texture.
glm::vec3 emission_at(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 bary, float footprint_m);

/// The mean of the material's textures over the parallelogram centre +- axis_u / 2 +-
/// axis_v / 2 of barycentrics (points outside the triangle are clamped onto it), as a BRDF.
engine::GltfBrdf footprint_brdf(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 centre,
                                glm::vec2 axis_u, glm::vec2 axis_v);

/// Hemispherical albedo (both lobes, engine::gltf_hemispherical_albedo) of footprint_brdf:
/// what a receiving element folds in as a diffuse reflector.
glm::vec3 footprint_albedo(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 centre, glm::vec2 axis_u,
                           glm::vec2 axis_v);

/// footprint_albedo over the whole triangle.
glm::vec3 triangle_albedo(const ReferenceScene& scene, const ShadingTriangle& tri);

/// The mean emitted radiance over the whole triangle (emission x the emissive texture's mean there).
glm::vec3 triangle_emission(const ReferenceScene& scene, const ShadingTriangle& tri);

/// Hemispherical albedo at one point for a footprint (a ray's hit).
glm::vec3 albedo_at(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 bary, float footprint_m);

}  // namespace gi
