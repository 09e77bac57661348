// Rooms and doorways from axis-aligned quads.
#include "rooms.h"

namespace scenegen {

void add_room(MeshBuilder& walls, MeshBuilder& floor, RoomMaterials m, glm::vec3 lo, glm::vec3 hi,
              const RoomOpenings& o) {
  floor.horizontal(m.floor, lo.y, lo.x, hi.x, lo.z, hi.z, 1.0f);
  walls.horizontal(m.ceiling, hi.y, lo.x, hi.x, lo.z, hi.z, -1.0f);
  const auto wall = [&](int own) { return own >= 0 ? own : m.walls; };
  walls.wall_x(wall(m.west), lo.x, lo.z, hi.z, lo.y, hi.y, 1.0f, o.west);
  walls.wall_x(wall(m.east), hi.x, lo.z, hi.z, lo.y, hi.y, -1.0f, o.east);
  walls.wall_z(wall(m.south), lo.z, lo.x, hi.x, lo.y, hi.y, 1.0f, o.south);
  walls.wall_z(wall(m.north), hi.z, lo.x, hi.x, lo.y, hi.y, -1.0f, o.north);
}

void add_doorway_x(MeshBuilder& walls, MeshBuilder& floor, RoomMaterials m, float x0, float x1, Opening o) {
  walls.wall_z(m.walls, o.a0, x0, x1, o.y0, o.y1, 1.0f);
  walls.wall_z(m.walls, o.a1, x0, x1, o.y0, o.y1, -1.0f);
  walls.horizontal(m.walls, o.y1, x0, x1, o.a0, o.a1, -1.0f);
  floor.horizontal(m.floor, o.y0, x0, x1, o.a0, o.a1, 1.0f);
}

void add_doorway_z(MeshBuilder& walls, MeshBuilder& floor, RoomMaterials m, float z0, float z1, Opening o) {
  walls.wall_x(m.walls, o.a0, z0, z1, o.y0, o.y1, 1.0f);
  walls.wall_x(m.walls, o.a1, z0, z1, o.y0, o.y1, -1.0f);
  walls.horizontal(m.walls, o.y1, o.a0, o.a1, z0, z1, -1.0f);
  floor.horizontal(m.floor, o.y0, o.a0, o.a1, z0, z1, 1.0f);
}

}  // namespace scenegen
