#include "raytrace/scene_adapter.h"

#include <glm/glm.hpp>

namespace gi {

RtSceneData rt_scene_from(const BakeInput& input) {
  RtSceneData data;
  for (const BakeMesh& mesh : input.meshes) {
    RtGeometry geo;
    for (const BakePrimitive& prim : mesh.primitives) {
      const auto base = static_cast<std::uint32_t>(geo.positions.size());
      geo.positions.insert(geo.positions.end(), prim.positions.begin(), prim.positions.end());
      for (std::uint32_t i : prim.indices) geo.indices.push_back(base + i);
    }
    data.geometries.push_back(std::move(geo));
  }
  for (const BakeInstance& inst : input.instances) {
    if (inst.mesh >= data.geometries.size()) continue;
    data.instances.push_back(RtInstance{inst.mesh, inst.object_to_world, inst.mobility == BakeMobility::Dynamic,
                                        static_cast<std::uint64_t>(inst.id)});
  }
  return data;
}

ReferenceMaterial reference_material(const BakeMaterial& m) {
  ReferenceMaterial out;
  out.brdf = engine::gltf_brdf(m.base_color, m.metallic, m.roughness, m.specular, m.specular_color);
  out.emission = m.emission;
  out.double_sided = m.double_sided;
  return out;
}

namespace {

// Per-triangle material indices of `mesh` (primitives concatenated); `override_material`
// >= 0 replaces them all. Index materials.size() - 1 is the default material.
std::vector<std::uint32_t> triangle_materials(const BakeMesh& mesh, int override_material, std::size_t material_count) {
  const auto default_index = static_cast<std::uint32_t>(material_count - 1);
  std::vector<std::uint32_t> out;
  for (const BakePrimitive& prim : mesh.primitives) {
    const int m = override_material >= 0 ? override_material : prim.material;
    const std::uint32_t index =
        m >= 0 && static_cast<std::size_t>(m) + 1 < material_count ? static_cast<std::uint32_t>(m) : default_index;
    out.insert(out.end(), prim.indices.size() / 3, index);
  }
  return out;
}

}  // namespace

ReferenceLight reference_light(const engine::Light& light, const glm::mat4& m) {
  ReferenceLight l;
  l.position = glm::vec3(m[3]);
  l.direction = -glm::normalize(glm::vec3(m[2]));  // lights emit along local -Z
  l.half_x = glm::normalize(glm::vec3(m[0])) * (0.5f * light.area_size_m.x);
  l.half_y = glm::normalize(glm::vec3(m[1])) * (0.5f * light.area_size_m.y);
  l.radiant = light.color * light.intensity;
  l.range_m = light.range_m;
  l.cos_outer = std::cos(light.outer_cone_rad);
  l.cos_inner = std::cos(std::min(light.inner_cone_rad, light.outer_cone_rad));
  switch (light.type) {
    case engine::LightType::Point:
      l.type = ReferenceLight::Type::Point;
      break;
    case engine::LightType::Spot:
      l.type = ReferenceLight::Type::Spot;
      break;
    case engine::LightType::Directional:
      l.type = ReferenceLight::Type::Directional;
      l.cos_disc = light.angular_radius_rad > 0.0f ? std::cos(std::min(light.angular_radius_rad, 1.5707963f)) : 1.0f;
      break;
    case engine::LightType::Area:
      l.type = ReferenceLight::Type::Area;
      break;
  }
  return l;
}

ReferenceScene reference_scene_from(const BakeInput& input) {
  ReferenceScene out;
  out.geometry = rt_scene_from(input);
  for (const BakeMaterial& m : input.materials) out.materials.push_back(reference_material(m));
  out.materials.push_back(reference_material(BakeMaterial{}));  // primitives without a material

  for (const BakeMesh& mesh : input.meshes) {
    std::vector<glm::vec3> normals;
    bool complete = true;
    for (const BakePrimitive& prim : mesh.primitives) {
      complete = complete && prim.normals.size() == prim.positions.size();
      normals.insert(normals.end(), prim.normals.begin(), prim.normals.end());
    }
    if (!complete) normals.clear();  // flat shading for the whole mesh
    out.normals.push_back(std::move(normals));
    out.triangle_material.push_back(triangle_materials(mesh, -1, out.materials.size()));
  }
  // Instances that override the material get a geometry of their own.
  std::size_t instance = 0;
  for (const BakeInstance& inst : input.instances) {
    if (inst.mesh >= input.meshes.size()) continue;
    if (inst.material_override >= 0) {
      const auto geo = static_cast<std::uint32_t>(out.geometry.geometries.size());
      out.geometry.geometries.push_back(out.geometry.geometries[inst.mesh]);
      out.normals.push_back(out.normals[inst.mesh]);
      out.triangle_material.push_back(
          triangle_materials(input.meshes[inst.mesh], inst.material_override, out.materials.size()));
      out.geometry.instances[instance].geometry = geo;
    }
    ++instance;
  }
  for (const BakeLight& l : input.lights)
    if (l.light.enabled) out.lights.push_back(reference_light(l.light, l.light_to_world));
  out.sky_radiance = input.environment.sky_radiance;
  out.sky_gradient = input.environment.sky_gradient;
  return out;
}

}  // namespace gi
