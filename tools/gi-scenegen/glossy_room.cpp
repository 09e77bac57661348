// An 8 x 3 x 5 m room with a glossy dielectric floor (roughness 0.15) lit by two point
// lights, with a coloured wall and two blocks to see reflected in the floor.
#include <glm/gtc/constants.hpp>

#include "rooms.h"
#include "scene_builder.h"
#include "scenes.h"

namespace scenegen {

engine::SceneAsset glossy_room() {
  SceneBuilder b;
  const int wall = b.material("plaster", {0.7f, 0.7f, 0.7f});
  const int glossy = b.material("polished_floor", {0.45f, 0.42f, 0.4f}, 0.15f, 0.0f);
  const int blue = b.material("blue_paint", {0.15f, 0.25f, 0.6f});
  const int block_mat = b.material("block_orange", {0.8f, 0.45f, 0.15f});

  MeshBuilder walls, floor;
  add_room(walls, floor, {glossy, wall, wall}, {-4, 0, -2.5f}, {4, 3, 2.5f}, {});
  b.add_mesh_node("room", walls, engine::Mobility::Static);
  b.add_mesh_node("glossy_floor", floor, engine::Mobility::Static);
  MeshBuilder accent;  // a blue panel in front of the north wall
  accent.wall_z(blue, 2.49f, -2.0f, 2.0f, 0.3f, 2.4f, -1.0f);
  b.add_mesh_node("blue_panel", accent, engine::Mobility::Static);

  MeshBuilder blocks;
  blocks.box(block_mat, {-1.2f, 0.4f, 0.8f}, {0.4f, 0.4f, 0.4f});
  blocks.box(block_mat, {1.5f, 0.7f, 1.2f}, {0.3f, 0.7f, 0.3f});
  b.add_mesh_node("blocks", blocks, engine::Mobility::Static);

  // 15 W/sr at 2.6 m: 15 / 2.6^2 = 2.2 W/m^2 on the floor below each light.
  b.add_light_node("light_warm", point_light(15.0f, {1.0f, 0.85f, 0.7f}), {-2.0f, 2.6f, 0});
  b.add_light_node("light_cool", point_light(15.0f, {0.75f, 0.85f, 1.0f}), {2.0f, 2.6f, -0.5f});

  b.add_camera_node("camera", {0.0f, 1.6f, -2.3f}, {0.0f, 0.3f, 1.5f}, glm::radians(70.0f));
  return b.take();
}

}  // namespace scenegen
