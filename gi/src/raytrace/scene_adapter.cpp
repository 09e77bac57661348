#include "raytrace/scene_adapter.h"

#include <glm/glm.hpp>

#include <cmath>

namespace gi {

namespace {

// The material index primitive `prim` renders with under `override_material` (-1: its
// own), or -1 for glTF's default.
int material_of(const BakeInput& input, const BakePrimitive& prim, int override_material) {
  const int m = override_material >= 0 ? override_material : prim.material;
  return m >= 0 && static_cast<std::size_t>(m) < input.materials.size() ? m : -1;
}

// The cut-outs of `mesh` rendered with `override_material` (-1: the primitives' own), or
// null when no triangle of it can be cut out.
std::shared_ptr<const RtAlphaCutout> mesh_cutout(const BakeInput& input, const BakeMesh& mesh, int override_material) {
  RtAlphaCutout c;
  std::vector<int> mask_of_material(input.materials.size(), -1);
  bool any = false;
  for (const BakePrimitive& prim : mesh.primitives) {
    const int m = material_of(input, prim, override_material);
    std::int32_t mask = -1;
    if (m >= 0 && input.materials[static_cast<std::size_t>(m)].cuts_out()) {
      const BakeMaterial& mat = input.materials[static_cast<std::size_t>(m)];
      if (mask_of_material[static_cast<std::size_t>(m)] < 0) {
        RtAlphaCutout::Mask k;
        k.factor = mat.base_alpha;
        k.cutoff = mat.alpha_mode == engine::AlphaMode::Blend ? 0.5f : mat.alpha_cutoff;
        const BakeTexture& t = mat.base_color_texture;
        if (t.present() && static_cast<std::size_t>(t.image) < input.images.size()) {
          const BakeImage& img = input.images[static_cast<std::size_t>(t.image)];
          k.width = img.width;
          k.height = img.height;
          k.alpha.resize(img.rgba8.size() / 4);
          for (std::size_t i = 0; i < k.alpha.size(); ++i) k.alpha[i] = img.rgba8[4 * i + 3];
          k.texcoord = t.texcoord;
          k.sampler = t.sampler;
          k.transform = t.transform;
        }
        mask_of_material[static_cast<std::size_t>(m)] = static_cast<int>(c.masks.size());
        c.masks.push_back(std::move(k));
      }
      mask = mask_of_material[static_cast<std::size_t>(m)];
      any = true;
    }
    c.triangle_mask.insert(c.triangle_mask.end(), prim.indices.size() / 3, mask);
  }
  if (!any) return nullptr;
  for (const BakePrimitive& prim : mesh.primitives) {  // UVs per vertex, 0 where a primitive has none
    for (int set = 0; set < 2; ++set) {
      const std::vector<glm::vec2>& uv = set == 0 ? prim.uv0 : prim.uv1;
      std::vector<glm::vec2>& out = set == 0 ? c.uv0 : c.uv1;
      for (std::size_t v = 0; v < prim.positions.size(); ++v) out.push_back(v < uv.size() ? uv[v] : glm::vec2(0.0f));
    }
  }
  return std::make_shared<const RtAlphaCutout>(std::move(c));
}

bool mesh_cuts_out(const BakeInput& input, const BakeMesh& mesh) {
  for (const BakePrimitive& prim : mesh.primitives) {
    const int m = material_of(input, prim, -1);
    if (m >= 0 && input.materials[static_cast<std::size_t>(m)].cuts_out()) return true;
  }
  return false;
}

}  // namespace

RtSceneData rt_scene_from(const BakeInput& input) {
  RtSceneData data;
  for (const BakeMesh& mesh : input.meshes) {
    RtGeometry geo;
    for (const BakePrimitive& prim : mesh.primitives) {
      const auto base = static_cast<std::uint32_t>(geo.positions.size());
      geo.positions.insert(geo.positions.end(), prim.positions.begin(), prim.positions.end());
      for (std::uint32_t i : prim.indices) geo.indices.push_back(base + i);
    }
    geo.cutout = mesh_cutout(input, mesh, -1);
    data.geometries.push_back(std::move(geo));
  }
  for (const BakeInstance& inst : input.instances) {
    if (inst.mesh >= data.geometries.size()) continue;
    std::uint32_t geometry = inst.mesh;
    // An instance whose override changes what is cut out gets a geometry of its own.
    if (inst.material_override >= 0) {
      const BakeMesh& mesh = input.meshes[inst.mesh];
      const int m = material_of(input, BakePrimitive{}, inst.material_override);
      if (mesh_cuts_out(input, mesh) || (m >= 0 && input.materials[static_cast<std::size_t>(m)].cuts_out())) {
        geometry = static_cast<std::uint32_t>(data.geometries.size());
        RtGeometry copy = data.geometries[inst.mesh];
        copy.cutout = mesh_cutout(input, mesh, inst.material_override);
        data.geometries.push_back(std::move(copy));
      }
    }
    data.instances.push_back(RtInstance{geometry, inst.object_to_world, inst.mobility == BakeMobility::Dynamic,
                                        static_cast<std::uint64_t>(inst.id)});
  }
  return data;
}

ReferenceMaterial reference_material(const BakeMaterial& m) {
  ReferenceMaterial out;
  out.brdf = engine::gltf_brdf(m.base_color, m.metallic, m.roughness, m.specular, m.specular_color);
  out.emission = m.emission;
  out.double_sided = m.double_sided;
  out.base_color = m.base_color;
  out.metallic = m.metallic;
  out.roughness = m.roughness;
  out.specular = m.specular;
  out.specular_color = m.specular_color;
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

namespace {

// The scene's mip chains, one per (image, encoding) a material reads, built on first use.
class TextureTable {
 public:
  TextureTable(const BakeInput& input, std::vector<TextureMips>& out) : input_(input), out_(out) {}
  MaterialTexture texture(const BakeTexture& t, bool srgb) {
    MaterialTexture m;
    if (!t.present() || static_cast<std::size_t>(t.image) >= input_.images.size()) return m;
    const std::size_t key = 2u * static_cast<std::size_t>(t.image) + (srgb ? 1u : 0u);
    if (index_.size() <= key) index_.resize(key + 1, -1);
    if (index_[key] < 0) {
      index_[key] = static_cast<int>(out_.size());
      out_.push_back(build_texture_mips(input_.images[static_cast<std::size_t>(t.image)], srgb));
    }
    m.mips = index_[key];
    m.texcoord = t.texcoord;
    m.sampler = t.sampler;
    m.transform = t.transform;
    return m;
  }

 private:
  const BakeInput& input_;
  std::vector<TextureMips>& out_;
  std::vector<int> index_;
};

// Per-vertex values of `mesh` (primitives concatenated) from `field`, or empty when a
// primitive lacks them.
template <class Field>
std::vector<glm::vec2> mesh_uvs(const BakeMesh& mesh, Field field) {
  std::vector<glm::vec2> out;
  for (const BakePrimitive& prim : mesh.primitives) {
    const std::vector<glm::vec2>& uv = prim.*field;
    if (uv.size() != prim.positions.size()) return {};
    out.insert(out.end(), uv.begin(), uv.end());
  }
  return out;
}

}  // namespace

namespace {

void add_materials(const BakeInput& input, ReferenceScene& out) {
  TextureTable textures(input, out.textures);
  for (const BakeMaterial& m : input.materials) {
    ReferenceMaterial r = reference_material(m);
    r.base_color_texture = textures.texture(m.base_color_texture, /*srgb=*/true);
    r.metallic_roughness_texture = textures.texture(m.metallic_roughness_texture, /*srgb=*/false);
    r.emissive_texture = textures.texture(m.emissive_texture, /*srgb=*/true);
    out.materials.push_back(r);
  }
  out.materials.push_back(reference_material(BakeMaterial{}));  // primitives without a material
}

}  // namespace

ReferenceScene material_scene_from(const BakeInput& input) {
  ReferenceScene out;
  add_materials(input, out);
  return out;
}

ShadingTriangle lookup_triangle(const BakeInput& input, const BakeInstance& instance, const BakePrimitive& prim,
                                std::size_t t, const glm::vec3 world[3]) {
  ShadingTriangle tri;
  const int m = material_of(input, prim, instance.material_override);
  tri.material = m >= 0 ? static_cast<std::uint32_t>(m) : static_cast<std::uint32_t>(input.materials.size());
  tri.p0 = world[0];
  tri.e1 = world[1] - world[0];
  tri.e2 = world[2] - world[0];
  const glm::vec3 c = glm::cross(tri.e1, tri.e2);
  tri.area_m2 = 0.5f * glm::length(c);
  tri.face_normal = tri.area_m2 > 0.0f ? glm::normalize(c) : glm::vec3(0.0f, 1.0f, 0.0f);
  tri.n0 = tri.n1 = tri.n2 = tri.face_normal;
  for (int set = 0; set < 2; ++set) {
    const std::vector<glm::vec2>& uv = set == 0 ? prim.uv0 : prim.uv1;
    if (uv.size() != prim.positions.size()) continue;
    glm::vec2* corner = set == 0 ? tri.uv0 : tri.uv1;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = prim.indices[3 * t + static_cast<std::size_t>(k)];
      corner[k] = i < uv.size() ? uv[i] : glm::vec2(0.0f);
    }
    const glm::vec2 a = corner[1] - corner[0], b = corner[2] - corner[0];
    const float uv_area = 0.5f * std::fabs(a.x * b.y - a.y * b.x);
    const float per_m = tri.area_m2 > 0.0f ? std::sqrt(uv_area / tri.area_m2) : 0.0f;
    tri.uv_per_m[set] = std::isfinite(per_m) ? per_m : 0.0f;
  }
  return tri;
}

ReferenceScene reference_scene_from(const BakeInput& input) {
  ReferenceScene out;
  out.geometry = rt_scene_from(input);
  add_materials(input, out);

  const std::size_t geometries = out.geometry.geometries.size();
  out.normals.resize(geometries);
  out.triangle_material.resize(geometries);
  out.uv0.resize(geometries);
  out.uv1.resize(geometries);
  for (std::size_t g = 0; g < input.meshes.size(); ++g) {
    const BakeMesh& mesh = input.meshes[g];
    std::vector<glm::vec3> normals;
    bool complete = true;
    for (const BakePrimitive& prim : mesh.primitives) {
      complete = complete && prim.normals.size() == prim.positions.size();
      normals.insert(normals.end(), prim.normals.begin(), prim.normals.end());
    }
    if (!complete) normals.clear();  // flat shading for the whole mesh
    out.normals[g] = std::move(normals);
    out.triangle_material[g] = triangle_materials(mesh, -1, out.materials.size());
    out.uv0[g] = mesh_uvs(mesh, &BakePrimitive::uv0);
    out.uv1[g] = mesh_uvs(mesh, &BakePrimitive::uv1);
  }
  // Instances that override the material get a geometry of their own (rt_scene_from already
  // gave one to those whose override changes the cut-outs).
  std::size_t instance = 0;
  for (const BakeInstance& inst : input.instances) {
    if (inst.mesh >= input.meshes.size()) continue;
    if (inst.material_override >= 0) {
      std::uint32_t geo = out.geometry.instances[instance].geometry;
      if (geo == inst.mesh) {
        geo = static_cast<std::uint32_t>(out.geometry.geometries.size());
        out.geometry.geometries.push_back(out.geometry.geometries[inst.mesh]);
        out.normals.emplace_back();
        out.triangle_material.emplace_back();
        out.uv0.emplace_back();
        out.uv1.emplace_back();
        out.geometry.instances[instance].geometry = geo;
      }
      out.normals[geo] = out.normals[inst.mesh];
      out.uv0[geo] = out.uv0[inst.mesh];
      out.uv1[geo] = out.uv1[inst.mesh];
      out.triangle_material[geo] =
          triangle_materials(input.meshes[inst.mesh], inst.material_override, out.materials.size());
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
