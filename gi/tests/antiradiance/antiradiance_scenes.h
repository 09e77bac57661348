#pragma once
// Scenes of the antiradiance tests: the corridor with its door at a chosen angle, and small
// hand-built scenes (plates, thin walls) as BakeInput.
//   gi::BakeInput in = artest::corridor(0.0f);   // door shut

#include <engine/gltf.h>
#include <gi/bake_input.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

namespace artest {

/// The corridor door's hinge (its node translation) and its matrix at `degrees` open.
inline glm::mat4 door_matrix(float degrees) {
  return glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(6.0f, 0.0f, 5.4f)), glm::radians(degrees),
                     glm::vec3(0.0f, 1.0f, 0.0f));
}

inline std::uint32_t instance_named(const gi::BakeInput& in, const std::string& name) {
  for (std::size_t i = 0; i < in.instances.size(); ++i)
    if (in.instances[i].name == name) return static_cast<std::uint32_t>(i);
  return 0xffffffffu;
}

/// assets/corridor.gltf as bake input with the door at `degrees` (authored: 50).
inline gi::BakeInput corridor(float degrees) {
  auto asset = engine::load_gltf(std::string(GI_SOURCE_DIR "/assets/corridor.gltf"));
  if (!asset) std::abort();
  gi::BakeInput in = gi::bake_input_from(*asset);
  in.instances[instance_named(in, "door")].object_to_world = door_matrix(degrees);
  return in;
}

/// A quad c, c+u, c+u+v, c+v facing cross(u, v) as two triangles appended to `p`.
inline void add_quad(gi::BakePrimitive& p, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const auto base = static_cast<std::uint32_t>(p.positions.size());
  p.positions.insert(p.positions.end(), {c, c + u, c + u + v, c + v});
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// Adds a mesh of one primitive and one material, instanced once; returns the instance index.
inline std::uint32_t add_mesh(gi::BakeInput& in, const std::string& name, gi::BakePrimitive p, glm::vec3 albedo,
                              bool deforming, glm::mat4 m = glm::mat4(1.0f), glm::vec3 emission = glm::vec3(0.0f)) {
  gi::BakeMaterial mat;
  mat.name = name;
  mat.base_color = albedo;
  mat.specular = 0.0f;  // pure Lambertian: albedo = base colour
  mat.emission = emission;
  in.materials.push_back(mat);
  p.material = static_cast<int>(in.materials.size() - 1);
  in.meshes.push_back(gi::BakeMesh{name, {std::move(p)}});
  gi::BakeInstance inst;
  inst.name = name;
  inst.mesh = static_cast<std::uint32_t>(in.meshes.size() - 1);
  inst.object_to_world = m;
  inst.deforming = deforming;
  inst.id = static_cast<std::int64_t>(in.instances.size());
  in.instances.push_back(inst);
  return static_cast<std::uint32_t>(in.instances.size() - 1);
}

/// A box [lo, hi] with outward faces (a closed solid) as one primitive.
inline gi::BakePrimitive solid_box(glm::vec3 lo, glm::vec3 hi) {
  gi::BakePrimitive p;
  const glm::vec3 d = hi - lo;
  add_quad(p, lo, {0, d.y, 0}, {d.x, 0, 0});                  // z = lo, -z
  add_quad(p, {lo.x, lo.y, hi.z}, {d.x, 0, 0}, {0, d.y, 0});  // z = hi, +z
  add_quad(p, lo, {0, 0, d.z}, {0, d.y, 0});                  // x = lo, -x
  add_quad(p, {hi.x, lo.y, lo.z}, {0, d.y, 0}, {0, 0, d.z});  // x = hi, +x
  add_quad(p, lo, {d.x, 0, 0}, {0, 0, d.z});                  // y = lo, -y
  add_quad(p, {lo.x, hi.y, lo.z}, {0, 0, d.z}, {d.x, 0, 0});  // y = hi, +y
  return p;
}

/// A point light of `intensity` W/sr at `at`.
inline void add_point_light(gi::BakeInput& in, glm::vec3 at, float intensity) {
  gi::BakeLight l;
  l.name = "lamp";
  l.light.type = engine::LightType::Point;
  l.light.intensity = intensity;
  l.light_to_world = glm::translate(glm::mat4(1.0f), at);
  in.lights.push_back(l);
}

}  // namespace artest

namespace artest {

/// A door test scene: a lit plate (x = 0, facing +x, 1 x 1 m, albedo 0.8) under a point
/// light at (0.5, 0, 0); a static wall (solid, x in [1, 1 + wall_thickness], y and z in
/// [-2, 2]) with a 1 x 1 m opening (y, z in [-0.5, 0.5]); a door (solid panel filling the
/// opening: z in [-0.5 + gap, 0.5 - gap], y likewise, thickness min(0.04, wall)) hinged at
/// (1, *, -0.5) about +y, flagged deforming; a receiver plate behind (x = 2.2, facing -x,
/// 1 x 1 m, albedo 0.5). The receiver sees the lit plate only through the opening.
struct DoorScene {
  gi::BakeInput input;
  std::uint32_t door = 0;
  std::uint32_t receiver = 0;
};

inline glm::mat4 hinge_matrix(float degrees) {
  return glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(1.0f, 0.0f, -0.5f)), glm::radians(degrees),
                     glm::vec3(0.0f, 1.0f, 0.0f));
}

inline DoorScene door_scene(float degrees, float wall_thickness = 0.2f, float gap = 0.0f, bool light_in_door = false) {
  DoorScene s;
  gi::BakePrimitive lit;
  add_quad(lit, {0, -0.5f, -0.5f}, {0, 1, 0}, {0, 0, 1});
  add_mesh(s.input, "lit", lit, glm::vec3(0.8f), false);
  const float x0 = 1.0f, x1 = 1.0f + wall_thickness;
  gi::BakePrimitive wall = solid_box({x0, -2, -2}, {x1, 2, -0.5f});
  gi::BakePrimitive b2 = solid_box({x0, -2, 0.5f}, {x1, 2, 2});
  gi::BakePrimitive b3 = solid_box({x0, -2, -0.5f}, {x1, -0.5f, 0.5f});
  gi::BakePrimitive b4 = solid_box({x0, 0.5f, -0.5f}, {x1, 2, 0.5f});
  for (const gi::BakePrimitive* b : {&b2, &b3, &b4}) {
    const auto base = static_cast<std::uint32_t>(wall.positions.size());
    wall.positions.insert(wall.positions.end(), b->positions.begin(), b->positions.end());
    for (std::uint32_t i : b->indices) wall.indices.push_back(base + i);
  }
  add_mesh(s.input, "wall", wall, glm::vec3(0.5f), false);
  const float t = std::min(0.04f, wall_thickness);
  // Door in its hinge frame: x in [0, t], z in [gap, 1 - gap] (closed: rotation 0).
  s.door = add_mesh(s.input, "door", solid_box({0, -0.5f + gap, gap}, {t, 0.5f - gap, 1.0f - gap}), glm::vec3(0.6f),
                    true, hinge_matrix(degrees));
  gi::BakePrimitive r;
  add_quad(r, {2.2f, -0.5f, -0.5f}, {0, 0, 1}, {0, 1, 0});
  s.receiver = add_mesh(s.input, "receiver", r, glm::vec3(0.5f), false);
  if (light_in_door) {
    add_point_light(s.input, {1.0f + 0.5f * t, 0.0f, 0.0f}, 1.0f);  // inside the closed door panel
  } else {
    add_point_light(s.input, {0.5f, 0.0f, 0.0f}, 1.0f);
  }
  return s;
}

}  // namespace artest

#include "antiradiance/element_hierarchy.h"

namespace artest {

/// Area-weighted mean of `e` (one value per leaf) over the leaves of `instance`.
inline glm::vec3 instance_mean(const gi::ElementHierarchy& h, const gi::BakeInput& in, std::uint32_t instance,
                               const std::vector<glm::vec3>& e) {
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for (std::size_t l = 0; l < h.leaf_count(); ++l) {
    const std::size_t n = static_cast<std::size_t>(h.leaves[l]);
    if (h.node_instance[n] != static_cast<std::int32_t>(instance)) continue;
    sum += static_cast<double>(h.nodes[n].area_m2) * glm::dvec3(e[l]);
    area += static_cast<double>(h.nodes[n].area_m2);
  }
  (void)in;
  return glm::vec3(area > 0.0 ? sum / area : glm::dvec3(0.0));
}

}  // namespace artest
