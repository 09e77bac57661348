#pragma once
// Scenes built in code for the light-atlas tests: boxes of one material with lights inside.
//   engine::SceneAsset a = latest::closed_box(2.0f, 0.5f);

#include <engine/scene_asset.h>

namespace latest {

/// Adds an axis-aligned quad (two triangles) with corners c, c+u, c+u+v, c+v facing along
/// cross(u, v) to `p`.
inline void add_quad(engine::Primitive& p, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const auto base = static_cast<std::uint32_t>(p.positions.size());
  const glm::vec3 n = glm::normalize(glm::cross(u, v));
  p.positions.insert(p.positions.end(), {c, c + u, c + u + v, c + v});
  p.normals.insert(p.normals.end(), {n, n, n, n});
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// The six faces of the cube [-s/2, s/2]^3, facing inwards.
inline engine::Primitive inward_cube(float s) {
  engine::Primitive p;
  const float h = 0.5f * s;
  add_quad(p, {-h, -h, -h}, {0, 0, s}, {s, 0, 0});  // floor, +y
  add_quad(p, {-h, h, -h}, {s, 0, 0}, {0, 0, s});   // ceiling, -y
  add_quad(p, {-h, -h, -h}, {s, 0, 0}, {0, s, 0});  // z = -h, +z
  add_quad(p, {-h, -h, h}, {0, s, 0}, {s, 0, 0});   // z = +h, -z
  add_quad(p, {-h, -h, -h}, {0, s, 0}, {0, 0, s});  // x = -h, +x
  add_quad(p, {h, -h, -h}, {0, 0, s}, {0, s, 0});   // x = +h, -x
  return p;
}

/// A closed cube of side `size` (metres) of one grey Lambert-like material (base colour
/// `albedo`, roughness 1) with a point light of `intensity` W/sr at `light` (default: the
/// centre).
inline engine::SceneAsset closed_box(float size, float albedo, glm::vec3 light = glm::vec3(0.0f),
                                     float intensity = 1.0f) {
  engine::SceneAsset a;
  a.materials.push_back(engine::Material{.name = "grey", .base_color = glm::vec4(glm::vec3(albedo), 1.0f)});
  engine::Mesh mesh;
  mesh.name = "box";
  mesh.primitives.push_back(inward_cube(size));
  mesh.primitives.back().material = 0;
  a.meshes.push_back(std::move(mesh));
  a.nodes.push_back(engine::Node{.name = "box", .mesh = 0, .gi = {engine::Mobility::Static}});
  engine::NamedLight l;
  l.name = "lamp";
  l.light.type = engine::LightType::Point;
  l.light.intensity = intensity;
  a.lights.push_back(l);
  a.nodes.push_back(engine::Node{.name = "lamp", .translation = light, .light = 0});
  return a;
}

}  // namespace latest
