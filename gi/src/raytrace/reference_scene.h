#pragma once
// The reference path tracer's view of a scene: a snapshot in world space of every
// triangle with its shading data, the lights in engine units, and the emitters (emissive
// triangles) with a power-proportional sampling table. Plain data: tests build it by hand,
// reference_scene_from() (scene_adapter.h) fills it from a live engine scene.
//   gi::ReferenceScene s = gi::reference_scene_from(scene);
//   gi::ReferenceSceneIndex index = gi::index_reference_scene(s).value();

#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <engine/sky.h>

#include "raytrace/material_textures.h"
#include "raytrace/reference_brdf.h"
#include "raytrace/rt_scene_data.h"

namespace gi {

struct ReferenceMaterial {
  /// glTF's BRDF (engine/gltf_brdf.h); engine::gltf_lambertian(albedo) for a pure Lambertian.
  /// With textures: the BRDF of the factors alone; material_lookup.h multiplies them in.
  engine::GltfBrdf brdf = engine::gltf_brdf(glm::vec3(0.8f), 0.0f, 1.0f);
  glm::vec3 emission{0.0f};   ///< Emitted radiance, W/(m^2 sr), from the front face (x the emissive texture).
  bool double_sided = false;  ///< Back faces shade (and emit) like front faces.
  /// The factors the textures multiply (glTF metallic-roughness), read only when a texture is present.
  glm::vec3 base_color{0.8f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  float specular = 1.0f;
  glm::vec3 specular_color{1.0f};
  MaterialTexture base_color_texture;          ///< RGB x base_color (sRGB-decoded mips).
  MaterialTexture metallic_roughness_texture;  ///< G x roughness, B x metallic (linear mips).
  MaterialTexture emissive_texture;            ///< RGB x emission (sRGB-decoded mips).
  bool textured() const {
    return base_color_texture.present() || metallic_roughness_texture.present() || emissive_texture.present();
  }
};

/// A light in engine units (engine/components.h), world space.
struct ReferenceLight {
  enum class Type : std::uint8_t { Point, Spot, Directional, Area };
  Type type = Type::Point;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  ///< Unit emission direction (the light's -Z).
  glm::vec3 half_x{0.5f, 0.0f, 0.0f};      ///< Area: half the rectangle along its X axis (m).
  glm::vec3 half_y{0.0f, 0.0f, 0.5f};      ///< Area: half the rectangle along its Y axis (m).
  glm::vec3 radiant{1.0f};                 ///< W/sr (point, spot), W/m^2 (directional), W/(m^2 sr) (area).
  float range_m = 0.0f;                    ///< glTF range window; 0: unlimited.
  float cos_outer = 0.0f;                  ///< Spot cone.
  float cos_inner = 1.0f;
  /// Directional: cos of the angular radius of the source's disc (engine::Light::
  /// angular_radius_rad); 1: a single direction. Light arrives uniformly from the cone
  /// around -direction (sample_cone), `radiant` being the total irradiance.
  float cos_disc = 1.0f;
};

/// Everything the path tracer reads. Per geometry: world-independent shading data
/// (normals per vertex may be empty: flat shading); per triangle a material index.
struct ReferenceScene {
  RtSceneData geometry;
  std::vector<std::vector<glm::vec3>> normals;                ///< [geometry][vertex], object space.
  std::vector<std::vector<std::uint32_t>> triangle_material;  ///< [geometry][triangle] into materials.
  std::vector<ReferenceMaterial> materials;
  /// [geometry][vertex] material UV sets TEXCOORD_0 / TEXCOORD_1; the outer vector may be
  /// empty (no UVs anywhere) and an inner one empty (that geometry has none).
  std::vector<std::vector<glm::vec2>> uv0, uv1;
  std::vector<TextureMips> textures;  ///< What MaterialTexture::mips indexes.
  std::vector<ReferenceLight> lights;
  glm::vec3 sky_radiance{0.0f};      ///< Radiance of rays that escape, W/(m^2 sr) (a uniform sky).
  engine::SkyGradient sky_gradient;  ///< Added to it by the escaping direction's elevation (engine/sky.h).
};

/// One world-space triangle with what shading needs.
struct ShadingTriangle {
  glm::vec3 p0, e1, e2;   ///< p = p0 + u e1 + v e2.
  glm::vec3 n0, n1, n2;   ///< Unit world-space vertex normals (the face normal when flat).
  glm::vec3 face_normal;  ///< Unit, from the winding (front side).
  float area_m2 = 0.0f;
  std::uint32_t material = 0;
  std::int32_t emitter = -1;  ///< Index into ReferenceSceneIndex::emitters, or -1.
  glm::vec2 uv0[3]{};         ///< TEXCOORD_0 at the corners (0 when absent).
  glm::vec2 uv1[3]{};         ///< TEXCOORD_1 at the corners (0 when absent).
  /// UV units per metre on the surface, per set: sqrt(UV area / area); a footprint of w
  /// metres covers w x uv_per_m[set] in UV (the ray-cone mip choice, material_lookup.h).
  float uv_per_m[2]{0.0f, 0.0f};
};

/// Emissive triangles, sampled in proportion to their power (area x luminance x sides).
struct EmitterTable {
  std::vector<std::uint32_t> triangle;  ///< Index into ReferenceSceneIndex::triangles.
  std::vector<float> probability;       ///< Probability of picking each emitter.
  std::vector<float> cdf;               ///< Inclusive running sum of probability; back() == 1.
  /// Per emitter: 1 when the triangle is the emissive proxy of an area light (the renderer
  /// draws that light live), 0 when no light stands for it (its light on other surfaces
  /// exists only in the bakes: docs/scene-format.md, "What is baked and what is drawn live").
  std::vector<std::uint8_t> stands_for_light;
};

/// The snapshot flattened for shading: triangle index = instance_first[instance] + primitive.
struct ReferenceSceneIndex {
  std::vector<ShadingTriangle> triangles;
  std::vector<std::uint32_t> instance_first;
  EmitterTable emitters;
  /// Area lights that are also drawn as emissive geometry (the scene generator's emissive
  /// quad just in front of the light): the geometry stands for them, the analytic light is
  /// not sampled again, so their light is not counted twice.
  std::vector<bool> light_has_proxy;
  float scene_radius_m = 0.0f;  ///< Half the diagonal of the world bounds.
};

/// The triangles [first, end) of `instance` in ReferenceSceneIndex::triangles.
inline std::pair<std::uint32_t, std::uint32_t> instance_triangles(const ReferenceSceneIndex& index,
                                                                  std::size_t instance) {
  const std::uint32_t first = index.instance_first[instance];
  const std::uint32_t end = instance + 1 < index.instance_first.size()
                                ? index.instance_first[instance + 1]
                                : static_cast<std::uint32_t>(index.triangles.size());
  return {first, end};
}

/// Flattens the scene. Errors: inconsistent sizes, indices out of range, non-finite values.
engine::Result<ReferenceSceneIndex> index_reference_scene(const ReferenceScene& scene);

/// Rebuilds index.emitters (and each triangle's `emitter`) from the emissive triangles of the
/// static instances only: a bake of the static world must not sample the light of a dynamic
/// object's emissive surface at its authored pose (it moves; its caster is not in the bake).
void keep_static_emitters(const ReferenceScene& scene, ReferenceSceneIndex& index);

/// The BRDF of a hit on triangle `tri` at barycentrics (u, v), seen from the side of wo.
/// `front` says whether wo lies on the front side. The material's textures are read there
/// (material_lookup.h) for a footprint of `footprint_m` metres (0: the finest mip level).
ReferenceBrdf shading_brdf(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 uv, bool front,
                           float footprint_m = 0.0f);

}  // namespace gi
