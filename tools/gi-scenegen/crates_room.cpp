// A 6 x 3 x 6 m room under a static ceiling area light, with five movable crates (one
// red) and a white static "statue" made of stacked blocks.
#include <glm/gtc/constants.hpp>

#include "rooms.h"
#include "scene_builder.h"
#include "scenes.h"

namespace scenegen {

engine::SceneAsset crates_room() {
  SceneBuilder b;
  const int wall = b.material("plaster", {0.7f, 0.7f, 0.7f});
  const int floor_mat = b.material("floor", {0.55f, 0.55f, 0.55f});
  const int wood = b.material("crate_wood", {0.62f, 0.45f, 0.28f});
  const int red = b.material("crate_red", {0.75f, 0.06f, 0.05f});
  const int statue_mat = b.material("statue_white", {0.85f, 0.85f, 0.85f});
  // 1 x 1 m panel, radiance 30: about 30 * 1 / 3^2 = 3.3 W/m^2 on the floor below it.
  const glm::vec3 radiance(30.0f, 28.5f, 26.0f);
  const int lamp = b.material("ceiling_panel", {0.8f, 0.8f, 0.8f}, 1.0f, 0.0f, radiance);

  MeshBuilder walls, floor;
  add_room(walls, floor, {floor_mat, wall, wall}, {-3, 0, -3}, {3, 3, 3}, {});
  b.add_mesh_node("room", walls, engine::Mobility::Static);
  b.add_mesh_node("room_floor", floor, engine::Mobility::Static);

  MeshBuilder panel;
  panel.horizontal(lamp, 3.0f - 1e-4f, -0.5f, 0.5f, -0.5f, 0.5f, -1.0f);
  b.add_mesh_node("ceiling_panel", panel, engine::Mobility::Static);
  b.add_light_node("ceiling_light", area_light({1.0f, 1.0f}, radiance), {0, 3.0f, 0}, facing({0, -1, 0}, {1, 0, 0}));

  // The statue: plinth, body and head, static.
  MeshBuilder statue;
  statue.box(statue_mat, {0, 0.2f, 0}, {0.35f, 0.2f, 0.35f});
  statue.box(statue_mat, {0, 0.9f, 0}, {0.2f, 0.5f, 0.2f});
  statue.box(statue_mat, {0, 1.55f, 0}, {0.14f, 0.15f, 0.14f});
  b.add_mesh_node("statue", statue, engine::Mobility::Static, {-1.2f, 0, 1.2f});

  // Crates: 0.5 m cubes, local origin at the bottom centre, dynamic.
  MeshBuilder crate, red_crate;
  crate.tessellated_box(wood, {0, 0.25f, 0}, glm::vec3(0.25f), 6);  // per-vertex indirect light needs inner vertices
  red_crate.tessellated_box(red, {0, 0.25f, 0}, glm::vec3(0.25f), 6);
  const int crate_mesh = b.add_mesh("crate", crate);
  const int red_mesh = b.add_mesh("crate_red", red_crate);
  b.add_instance_node("crate_red", red_mesh, engine::Mobility::Dynamic, {0.8f, 0, -0.6f});
  b.add_instance_node("crate_1", crate_mesh, engine::Mobility::Dynamic, {1.5f, 0, 0.7f},
                      glm::angleAxis(glm::radians(20.0f), glm::vec3(0, 1, 0)));
  b.add_instance_node("crate_2", crate_mesh, engine::Mobility::Dynamic, {-0.4f, 0, -1.6f});
  b.add_instance_node("crate_3", crate_mesh, engine::Mobility::Dynamic, {2.1f, 0, -2.0f});
  b.add_instance_node("crate_4", crate_mesh, engine::Mobility::Dynamic, {2.1f, 0.5f, -2.0f},
                      glm::angleAxis(glm::radians(35.0f), glm::vec3(0, 1, 0)));

  b.add_camera_node("camera", {-2.5f, 1.7f, -2.6f}, {0.5f, 0.6f, 0.5f}, glm::radians(65.0f));
  return b.take();
}

}  // namespace scenegen
