#pragma once
// A small level built in code for the demo tests: a 10 m x 6 m room (inner faces at
// x = +-5, z = +-3, floor at y = 0, ceiling at y = 3) with walls made of boxes, a camera
// at eye height looking along -Z, a ceiling light and crates where the test puts them.

#include <vector>

#include <glm/glm.hpp>

#include <engine/scene.h>

namespace demo_test {

struct CrateSpec {
  glm::vec3 center;
  float half_m = 0.4f;
};

inline engine::Mesh box_mesh(const glm::vec3& half) {
  engine::Primitive p;
  for (int i = 0; i < 8; ++i)
    p.positions.push_back({(i & 1) ? half.x : -half.x, (i & 2) ? half.y : -half.y, (i & 4) ? half.z : -half.z});
  // Two triangles per face: -x, +x, -y, +y, -z, +z.
  const std::uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                     {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : faces) p.indices.insert(p.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  engine::Mesh m;
  m.primitives.push_back(std::move(p));
  return m;
}

/// The room with `crates`; the camera stands at `eye` looking along -Z.
inline engine::Scene make_room(const std::vector<CrateSpec>& crates, glm::vec3 eye = {0.0f, 1.6f, 2.0f}) {
  engine::SceneAsset a;
  a.source = "test_room";
  auto add_box = [&](const char* name, glm::vec3 center, glm::vec3 half, engine::Mobility mobility) {
    a.meshes.push_back(box_mesh(half));
    engine::Node n;
    n.name = name;
    n.translation = center;
    n.mesh = static_cast<int>(a.meshes.size() - 1);
    n.gi.mobility = mobility;
    a.nodes.push_back(n);
  };
  add_box("floor", {0, -0.1f, 0}, {5.2f, 0.1f, 3.2f}, engine::Mobility::Static);
  add_box("ceiling", {0, 3.1f, 0}, {5.2f, 0.1f, 3.2f}, engine::Mobility::Static);
  add_box("wall_west", {-5.1f, 1.5f, 0}, {0.1f, 1.5f, 3.2f}, engine::Mobility::Static);
  add_box("wall_east", {5.1f, 1.5f, 0}, {0.1f, 1.5f, 3.2f}, engine::Mobility::Static);
  add_box("wall_north", {0, 1.5f, -3.1f}, {5.2f, 1.5f, 0.1f}, engine::Mobility::Static);
  add_box("wall_south", {0, 1.5f, 3.1f}, {5.2f, 1.5f, 0.1f}, engine::Mobility::Static);
  for (const CrateSpec& c : crates) add_box("crate", c.center, glm::vec3(c.half_m), engine::Mobility::Dynamic);
  a.lights.push_back({"lamp", engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}});
  engine::Node lamp;
  lamp.name = "lamp";
  lamp.translation = {0, 2.8f, 0};
  lamp.light = 0;
  a.nodes.push_back(lamp);
  a.cameras.push_back({"camera", engine::Camera{}});
  engine::Node cam;
  cam.name = "camera";
  cam.translation = eye;
  cam.camera = 0;
  a.nodes.push_back(cam);
  return engine::instantiate(std::move(a));
}

}  // namespace demo_test
