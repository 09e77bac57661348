// A room, a closed light alcove and an L-shaped corridor, built so that the room's light
// reaches the corridor floor only through two reflections first (see assets/README.md).
//
// Top view (x right, z up), walls between room and annex are 0.2 m thick (x in [6, 6.2]):
//
//   z=5.6      +-------------------+        corridor leg 1: x [6.2, 9.2], z [4.2, 5.6]
//   door ajar  |=>                 |        corridor leg 2: x [7.8, 9.2], z [-3, 4.2]
//   z=4.2  ----+-----------+       |
//   room       |           |  leg  |        alcove: x [6.2, 7.4], z [0.3, 3.0], its only
//   x [0,6]    | alcove    |   2   |        opening faces the room (z [0.5, 1.5]); the lamp
//   z [0,6]    | lamp=>    |       |        hangs on the alcove's room-side wall and
//              +-----------+       |        faces +x, away from the room.
//   z=-3                   +-------+
//
// Everything the lamp sees lies in x > 6.2 inside the alcove, and every corridor point lies
// in x > 6.2 inside the corridor: a segment between two such points never leaves x > 6.2,
// so it must cross the closed walls that separate alcove and corridor. Hence no corridor
// point sees the lamp or any surface the lamp lights directly.
#include <glm/gtc/constants.hpp>

#include "rooms.h"
#include "scene_builder.h"
#include "scenes.h"

namespace scenegen {

namespace {

// The L-shaped corridor: leg 1 leaves the door along +x, leg 2 turns the corner along -z.
void add_l_corridor(SceneBuilder& b, int floor_mat, int wall, const Opening& door_opening) {
  using namespace corridor_layout;
  MeshBuilder corridor_walls, corridor_floor;
  corridor_floor.horizontal(floor_mat, 0.0f, kAnnexX, 9.2f, 4.2f, 5.6f, 1.0f);
  corridor_floor.horizontal(floor_mat, 0.0f, 7.8f, 9.2f, -3.0f, 4.2f, 1.0f);
  corridor_walls.horizontal(wall, kHeight, kAnnexX, 9.2f, 4.2f, 5.6f, -1.0f);
  corridor_walls.horizontal(wall, kHeight, 7.8f, 9.2f, -3.0f, 4.2f, -1.0f);
  corridor_walls.wall_x(wall, kAnnexX, 4.2f, 5.6f, 0.0f, kHeight, 1.0f, {door_opening});
  corridor_walls.wall_z(wall, 5.6f, kAnnexX, 9.2f, 0.0f, kHeight, -1.0f);
  corridor_walls.wall_x(wall, 9.2f, -3.0f, 5.6f, 0.0f, kHeight, -1.0f);
  corridor_walls.wall_z(wall, -3.0f, 7.8f, 9.2f, 0.0f, kHeight, 1.0f);
  corridor_walls.wall_x(wall, 7.8f, -3.0f, 4.2f, 0.0f, kHeight, 1.0f);
  corridor_walls.wall_z(wall, 4.2f, kAnnexX, 7.8f, 0.0f, kHeight, 1.0f);
  b.add_mesh_node("corridor_walls", corridor_walls, engine::Mobility::Static);
  b.add_mesh_node("corridor_floor", corridor_floor, engine::Mobility::Static);
}

}  // namespace

engine::SceneAsset corridor() {
  using namespace corridor_layout;
  SceneBuilder b;
  const int wall = b.material("plaster", {0.7f, 0.7f, 0.7f});
  const int floor_mat = b.material("floor", {0.7f, 0.68f, 0.64f});
  const int door_mat = b.material("door_wood", {0.72f, 0.62f, 0.5f});
  const glm::vec3 radiance(40.0f);
  const int lamp_mat = b.material("lamp", {0.7f, 0.7f, 0.7f}, 1.0f, 0.0f, radiance);
  const RoomMaterials mats{floor_mat, wall, wall};

  const Opening alcove_opening{0.5f, 1.5f, 0.0f, 2.2f};
  const Opening door_opening{4.4f, 5.4f, 0.0f, 2.1f};

  // The room, with both openings in its east wall, and the two tunnels through that wall.
  MeshBuilder room, room_floor;
  add_room(room, room_floor, mats, {0, 0, 0}, {kRoomSize, kHeight, kRoomSize},
           {{}, {alcove_opening, door_opening}, {}, {}});
  add_doorway_x(room, room_floor, mats, kRoomSize, kAnnexX, alcove_opening);
  add_doorway_x(room, room_floor, mats, kRoomSize, kAnnexX, door_opening);
  b.add_mesh_node("room", room, engine::Mobility::Static);
  b.add_mesh_node("room_floor", room_floor, engine::Mobility::Static);

  // The closed alcove: its only opening is the tunnel to the room.
  MeshBuilder alcove, alcove_floor;
  add_room(alcove, alcove_floor, mats, {kAnnexX, 0, 0.3f}, {7.4f, 2.6f, 3.0f}, {{alcove_opening}, {}, {}, {}});
  b.add_mesh_node("alcove", alcove, engine::Mobility::Static);
  b.add_mesh_node("alcove_floor", alcove_floor, engine::Mobility::Static);

  add_l_corridor(b, floor_mat, wall, door_opening);

  // The door, left ajar: hinged at the room side of the doorway (x = 6, z = 5.4), swung
  // 50 degrees into the room. The node's origin is the hinge and its local +y the hinge
  // axis, so a game opens or closes it by rotating the node about y alone (0 degrees: shut,
  // the leaf spanning the doorway's z [4.41, 5.39]). Flagged gi.region "deforming": its
  // light exchange with the room and corridor is solved at runtime by antiradiance
  // (docs/antiradiance.md), not baked.
  MeshBuilder door;
  door.box(door_mat, {-0.02f, 1.025f, -0.5f}, {0.02f, 1.025f, 0.49f});
  const int door_node = b.add_mesh_node("door", door, engine::Mobility::Static, {kRoomSize, 0.0f, 5.4f},
                                        glm::angleAxis(glm::radians(50.0f), glm::vec3(0, 1, 0)));
  b.asset().nodes[static_cast<std::size_t>(door_node)].gi.region = engine::GiRegion::Deforming;

  // The lamp: 0.8 x 0.8 m on the alcove's room-side wall, facing +x (away from the room).
  const float x_lamp = kAnnexX + 1e-4f;
  MeshBuilder lamp_quad;
  lamp_quad.quad(lamp_mat, {x_lamp, 1.4f, 1.9f}, {x_lamp, 1.4f, 2.7f}, {x_lamp, 2.2f, 2.7f}, {x_lamp, 2.2f, 1.9f},
                 {1, 0, 0});
  b.add_mesh_node("alcove_lamp", lamp_quad, engine::Mobility::Static);
  b.add_light_node("alcove_light", area_light({0.8f, 0.8f}, radiance), {kAnnexX, 1.8f, 2.3f},
                   facing({1, 0, 0}, {0, 0, 1}));

  b.add_camera_node("camera", {8.5f, 1.6f, -2.6f}, {8.0f, 1.0f, 5.0f}, glm::radians(60.0f));
  return b.take();
}

}  // namespace scenegen
