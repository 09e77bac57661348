#pragma once
// Rooms (inward-facing boxes with door openings) and doorways (the short tunnels through
// a wall between two rooms).
//   scenegen::RoomOpenings doors;  doors.east.push_back({3.5f, 4.5f, 0.0f, 2.1f});
//   scenegen::add_room(walls, floor, {white, white, white}, {0, 0, 0}, {8, 3, 8}, doors);

#include <vector>

#include "scene_builder.h"

namespace scenegen {

/// Openings per wall: west (x = min.x), east (x = max.x), south (z = min.z), north (z = max.z).
/// West/east openings run along z, south/north along x.
struct RoomOpenings {
  std::vector<Opening> west, east, south, north;
};

/// Materials of a room's surfaces. `west` .. `north` give one wall a material of its own
/// (-1: `walls`); doorway tunnels use `walls`.
struct RoomMaterials {
  int floor, walls, ceiling;
  int west = -1, east = -1, south = -1, north = -1;
};

/// Floor into `floor` and walls + ceiling into `walls`, all facing inside the box [min, max].
void add_room(MeshBuilder& walls, MeshBuilder& floor, RoomMaterials materials, glm::vec3 min, glm::vec3 max,
              const RoomOpenings& openings);

/// Tunnel through a wall lying between x0 and x1, for an opening spanning z in [o.a0, o.a1]
/// and y in [o.y0, o.y1]: two side walls, a lintel and a floor strip, facing inside.
void add_doorway_x(MeshBuilder& walls, MeshBuilder& floor, RoomMaterials materials, float x0, float x1, Opening o);
/// The same for a wall lying between z0 and z1 (opening along x).
void add_doorway_z(MeshBuilder& walls, MeshBuilder& floor, RoomMaterials materials, float z0, float z1, Opening o);

}  // namespace scenegen
