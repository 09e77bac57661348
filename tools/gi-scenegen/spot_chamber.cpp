// A closed 4 x 3 x 4 m chamber lit only by one spot light hanging under the ceiling and
// pointing down at a pedestal.
#include <glm/gtc/constants.hpp>

#include "rooms.h"
#include "scene_builder.h"
#include "scenes.h"

namespace scenegen {

engine::SceneAsset spot_chamber() {
  SceneBuilder b;
  const int wall = b.material("plaster", {0.7f, 0.7f, 0.7f});
  const int floor_mat = b.material("stone_floor", {0.6f, 0.58f, 0.55f});
  const int pedestal_mat = b.material("pedestal", {0.75f, 0.72f, 0.68f});

  MeshBuilder walls, floor;
  add_room(walls, floor, {floor_mat, wall, wall}, {-2, 0, -2}, {2, 3, 2}, {});
  b.add_mesh_node("chamber", walls, engine::Mobility::Static);
  b.add_mesh_node("chamber_floor", floor, engine::Mobility::Static);
  MeshBuilder pedestal;
  pedestal.box(pedestal_mat, {0, 0.45f, 0}, {0.3f, 0.45f, 0.3f});
  b.add_mesh_node("pedestal", pedestal, engine::Mobility::Static);

  // 12 W/sr = 8196 cd: 12 / 2.9^2 = 1.4 W/m^2 on the floor under the lamp.
  engine::Light spot;
  spot.type = engine::LightType::Spot;
  spot.intensity = 12.0f;
  spot.color = {1.0f, 0.95f, 0.85f};
  spot.inner_cone_rad = glm::radians(30.0f);
  spot.outer_cone_rad = glm::radians(40.0f);
  b.add_light_node("spot", spot, {0, 2.9f, 0}, facing({0, -1, 0}, {1, 0, 0}));

  b.add_camera_node("camera", {1.7f, 1.7f, 1.7f}, {0, 0.6f, 0}, glm::radians(65.0f));
  return b.take();
}

}  // namespace scenegen
