#include "bundle/geometry_hash.h"

#include <cstdint>
#include <span>

#include "io/content_hash.h"
#include "uv/atlas_input.h"

namespace gi {

namespace {

void add_vec(ContentHash& h, const glm::vec3& v) {
  h.add_value(v.x);
  h.add_value(v.y);
  h.add_value(v.z);
}

void add_material(ContentHash& h, const engine::SceneAsset& scene, int index) {
  const bool valid = index >= 0 && static_cast<std::size_t>(index) < scene.materials.size();
  const engine::Material m = valid ? scene.materials[static_cast<std::size_t>(index)] : engine::Material{};
  for (int c = 0; c < 4; ++c) h.add_value(m.base_color[c]);
  h.add_value(m.metallic);
  h.add_value(m.roughness);
  add_vec(h, m.emissive);
  h.add_value(m.specular_factor);
  add_vec(h, m.specular_color_factor);
  const int t = m.base_color_texture;
  if (t >= 0 && static_cast<std::size_t>(t) < scene.images.size()) {
    const engine::Image& image = scene.images[static_cast<std::size_t>(t)];
    h.add_value(image.width);
    h.add_value(image.height);
    h.add_values(std::span<const std::uint8_t>(image.rgba8));
  } else {
    h.add_value(std::int32_t{-1});
  }
}

void add_primitive(ContentHash& h, const engine::Primitive& p) {
  const bool has_normals = p.normals.size() == p.positions.size();
  h.add_value(static_cast<std::uint64_t>(p.indices.size()));
  h.add_value(static_cast<std::uint8_t>(has_normals));
  for (const std::uint32_t i : p.indices) {
    if (i >= p.positions.size()) {
      h.add_value(std::uint8_t{0});
      h.add_value(i);
      continue;
    }
    h.add_value(std::uint8_t{1});
    add_vec(h, p.positions[i]);
    if (has_normals) add_vec(h, p.normals[i]);
  }
}

}  // namespace

std::string scene_geometry_hash(const engine::SceneAsset& scene) {
  ContentHash h;
  // v2: glTF's BRDF (engine/gltf_brdf.h) replaced Lambert + GGX; a bundle baked with the old
  // reflectances is stale even where the geometry is the same.
  h.add_string("gi scene geometry v2");
  for (std::size_t n = 0; n < scene.nodes.size(); ++n) {
    const engine::Node& node = scene.nodes[n];
    if (node.mesh < 0 || static_cast<std::size_t>(node.mesh) >= scene.meshes.size()) continue;
    if (node.gi.mobility == engine::Mobility::Dynamic) continue;
    h.add_value(static_cast<std::uint64_t>(n));
    const glm::mat4 world = node_world_matrix(scene, static_cast<int>(n));
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(world[c][r]);
    const engine::Mesh& mesh = scene.meshes[static_cast<std::size_t>(node.mesh)];
    h.add_value(static_cast<std::uint64_t>(mesh.primitives.size()));
    for (const engine::Primitive& p : mesh.primitives) {
      add_primitive(h, p);
      add_material(h, scene, p.material);
    }
  }
  return h.hex();
}

std::string static_lights_hash(const engine::SceneAsset& scene) {
  ContentHash h;
  h.add_string("gi static lights v1");
  for (std::size_t n = 0; n < scene.nodes.size(); ++n) {
    const engine::Node& node = scene.nodes[n];
    if (node.light < 0 || static_cast<std::size_t>(node.light) >= scene.lights.size()) continue;
    const engine::Light& l = scene.lights[static_cast<std::size_t>(node.light)].light;
    if (!l.enabled || l.moves) continue;
    h.add_value(static_cast<std::uint64_t>(n));
    const glm::mat4 world = node_world_matrix(scene, static_cast<int>(n));
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(world[c][r]);
    h.add_value(static_cast<std::uint8_t>(l.type));
    add_vec(h, l.color);
    h.add_value(l.intensity);
    h.add_value(l.range_m);
    h.add_value(l.inner_cone_rad);
    h.add_value(l.outer_cone_rad);
    h.add_value(l.area_size_m.x);
    h.add_value(l.area_size_m.y);
  }
  return h.hex();
}

}  // namespace gi
