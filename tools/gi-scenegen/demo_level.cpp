// The demo level: a hub lit by static lights, a crate room with pushable crates (dynamic),
// a corridor with a glossy floor and a lamp room whose lamp swings (light_moves = true).
// Textures (textures.h): the hub's west wall is red brick beside its light floor (the
// corner light lights it: red bleeds onto the floor), a tartan rug lies in the hub, the
// lamp room has a wooden plank floor, and a wire-mesh grille (alphaMode MASK) hangs under
// the crate room's light, casting its cut-out shadow onto the floor. The rug and the grille
// are horizontal (they never block walking: the collision keeps wall-like triangles only)
// and added after the other nodes, which keep their indices.
//
// Top view (x right, z up):
//   z [16.4, 22.4]  lamp room    x [0, 8]    (swinging lamp hangs from a pivot node)
//   z [8.2, 16.2]   corridor     x [3, 5]    (dark polished floor, roughness 0.15)
//   z [0, 8]        hub          x [0, 8]    + crate room x [8.2, 14.2], z [1, 7] to the east
// Walls between spaces are 0.2 m thick; doorways are 1.6 m (hub-corridor-lamp room) and
// 1.2 m (hub-crate room) wide; the hub-corridor doorway has a door (deforming, key O).
#include <glm/gtc/constants.hpp>

#include "rooms.h"
#include "scene_builder.h"
#include "scenes.h"
#include "textures.h"

namespace scenegen {

namespace {

// The level's materials, created before any node (their indices are the asset's).
struct DemoMaterials {
  int wall, hub_floor_mat, crate_floor_mat, glossy, lamp_floor_mat, pillar_mat, wood, red, shade_mat;
  glm::vec3 panel_radiance;
  int panel_mat, brick_mat;
};

DemoMaterials demo_materials(SceneBuilder& b) {
  DemoMaterials m{};
  m.wall = b.material("plaster", {0.7f, 0.7f, 0.7f});
  m.hub_floor_mat = b.material("hub_tiles", {0.6f, 0.58f, 0.52f});
  m.crate_floor_mat = b.material("concrete", {0.5f, 0.5f, 0.5f});
  // Dark polished stone (issue 36's demo item): under a light grey albedo the diffuse term hid
  // the 0.04-F0 reflection of the lit doorway and walls; at 0.08 the reflection reads (README).
  m.glossy = b.material("polished_floor", {0.08f, 0.076f, 0.072f}, 0.15f, 0.0f);
  m.lamp_floor_mat = b.textured_material("lamp_room_boards", b.image(wood_planks_texture()));
  m.pillar_mat = b.material("pillar_white", {0.85f, 0.85f, 0.85f});
  m.wood = b.material("crate_wood", {0.62f, 0.45f, 0.28f});
  m.red = b.material("crate_red", {0.75f, 0.06f, 0.05f});
  m.shade_mat = b.material("lamp_shade", {0.3f, 0.3f, 0.32f}, 0.4f, 1.0f);
  m.panel_radiance = glm::vec3(20.0f, 19.0f, 17.5f);
  m.panel_mat = b.material("ceiling_panel", {0.8f, 0.8f, 0.8f}, 1.0f, 0.0f, m.panel_radiance);
  m.brick_mat = b.textured_material("brick", b.image(brick_texture()));
  return m;
}

constexpr Opening kHubCrateDoor{3.4f, 4.6f, 0.0f, 2.2f};  // along z, in the walls x = 8 / 8.2
constexpr Opening kNorthDoor{3.2f, 4.8f, 0.0f, 2.4f};     // along x, in walls z = 8..8.2 and 16.2..16.4

void add_hub(SceneBuilder& b, const DemoMaterials& m) {
  const Opening hub_crate_door = kHubCrateDoor, north_door = kNorthDoor;
  MeshBuilder hub, hub_floor;
  RoomMaterials hub_mats{m.hub_floor_mat, m.wall, m.wall};
  hub_mats.west = m.brick_mat;
  add_room(hub, hub_floor, hub_mats, {0, 0, 0}, {8, 3.5f, 8}, {{}, {hub_crate_door}, {}, {north_door}});
  add_doorway_x(hub, hub_floor, {m.hub_floor_mat, m.wall, m.wall}, 8.0f, 8.2f, hub_crate_door);
  add_doorway_z(hub, hub_floor, {m.hub_floor_mat, m.wall, m.wall}, 8.0f, 8.2f, north_door);
  b.add_mesh_node("hub", hub, engine::Mobility::Static);
  b.add_mesh_node("hub_floor", hub_floor, engine::Mobility::Static);
  MeshBuilder pillars;
  pillars.box(m.pillar_mat, {2.0f, 1.75f, 5.5f}, {0.3f, 1.75f, 0.3f});
  pillars.box(m.pillar_mat, {6.0f, 1.75f, 5.5f}, {0.3f, 1.75f, 0.3f});
  b.add_mesh_node("hub_pillars", pillars, engine::Mobility::Static);
  MeshBuilder panel;
  panel.horizontal(m.panel_mat, 3.5f - 1e-4f, 3.25f, 4.75f, 3.25f, 4.75f, -1.0f);
  b.add_mesh_node("hub_ceiling_panel", panel, engine::Mobility::Static);
  // 1.5 x 1.5 m panel, radiance 20: about 20 * 2.25 / 3.5^2 = 3.7 W/m^2 under it.
  b.add_light_node("hub_panel_light", area_light({1.5f, 1.5f}, m.panel_radiance), {4.0f, 3.5f, 4.0f},
                   facing({0, -1, 0}, {1, 0, 0}));
  b.add_light_node("hub_corner_light", point_light(8.0f, {1.0f, 0.8f, 0.6f}), {0.8f, 3.0f, 7.2f});
}

void add_crate_room(SceneBuilder& b, const DemoMaterials& m) {
  const Opening hub_crate_door = kHubCrateDoor;
  MeshBuilder crate_room, crate_floor;
  add_room(crate_room, crate_floor, {m.crate_floor_mat, m.wall, m.wall}, {8.2f, 0, 1}, {14.2f, 3, 7},
           {{hub_crate_door}, {}, {}, {}});
  b.add_mesh_node("crate_room", crate_room, engine::Mobility::Static);
  b.add_mesh_node("crate_room_floor", crate_floor, engine::Mobility::Static);
  b.add_light_node("crate_room_light", point_light(12.0f), {11.2f, 2.8f, 4.0f});
  MeshBuilder crate, red_crate;
  // Tessellated: the crates get per-vertex indirect light (basis radiance fields).
  crate.tessellated_box(m.wood, {0, 0.25f, 0}, glm::vec3(0.25f), 6);
  red_crate.tessellated_box(m.red, {0, 0.25f, 0}, glm::vec3(0.25f), 6);
  const int crate_mesh = b.add_mesh("crate", crate);
  const int red_mesh = b.add_mesh("crate_red", red_crate);
  // A white statue (static) beside the red crate: it turns pink from the crate's bounce.
  const int statue_mat = b.material("statue_white", {0.85f, 0.85f, 0.85f});
  MeshBuilder statue;
  statue.box(statue_mat, {0, 0.2f, 0}, {0.3f, 0.2f, 0.3f});
  statue.box(statue_mat, {0, 0.9f, 0}, {0.18f, 0.5f, 0.18f});
  statue.box(statue_mat, {0, 1.55f, 0}, {0.13f, 0.15f, 0.13f});
  b.add_mesh_node("statue", statue, engine::Mobility::Static, {9.2f, 0, 2.0f});
  b.add_instance_node("crate_red", red_mesh, engine::Mobility::Dynamic, {10.0f, 0, 3.2f});
  b.add_instance_node("crate_1", crate_mesh, engine::Mobility::Dynamic, {11.5f, 0, 5.0f},
                      glm::angleAxis(glm::radians(15.0f), glm::vec3(0, 1, 0)));
  b.add_instance_node("crate_2", crate_mesh, engine::Mobility::Dynamic, {12.6f, 0, 2.2f});
  b.add_instance_node("crate_3", crate_mesh, engine::Mobility::Dynamic, {13.3f, 0, 6.0f});
  b.add_instance_node("crate_4", crate_mesh, engine::Mobility::Dynamic, {12.6f, 0.5f, 2.2f},
                      glm::angleAxis(glm::radians(30.0f), glm::vec3(0, 1, 0)));
}

void add_corridor(SceneBuilder& b, const DemoMaterials& m) {
  const Opening north_door = kNorthDoor;
  MeshBuilder corridor, corridor_floor;
  add_room(corridor, corridor_floor, {m.glossy, m.wall, m.wall}, {3, 0, 8.2f}, {5, 3, 16.2f},
           {{}, {}, {north_door}, {north_door}});
  add_doorway_z(corridor, corridor_floor, {m.glossy, m.wall, m.wall}, 16.2f, 16.4f, north_door);
  b.add_mesh_node("corridor", corridor, engine::Mobility::Static);
  b.add_mesh_node("corridor_floor", corridor_floor, engine::Mobility::Static);
  b.add_light_node("corridor_light", point_light(6.0f), {4.0f, 2.8f, 12.2f});
}

// Lamp room with the swinging lamp: a dynamic pivot under the ceiling, a shade and a
// moving point light 1.2 m below it.
void add_lamp_room(SceneBuilder& b, const DemoMaterials& m) {
  const Opening north_door = kNorthDoor;
  MeshBuilder lamp_room, lamp_floor;
  add_room(lamp_room, lamp_floor, {m.lamp_floor_mat, m.wall, m.wall}, {0, 0, 16.4f}, {8, 3.5f, 22.4f},
           {{}, {}, {north_door}, {}});
  b.add_mesh_node("lamp_room", lamp_room, engine::Mobility::Static);
  b.add_mesh_node("lamp_room_floor", lamp_floor, engine::Mobility::Static);
  const int pivot = b.add_group_node("lamp_pivot", {4.0f, 3.5f, 19.4f}, engine::Mobility::Dynamic);
  MeshBuilder shade;
  shade.box(m.shade_mat, {0, 0, 0}, {0.2f, 0.1f, 0.2f});
  b.add_child_mesh_node("lamp_shade", b.add_mesh("lamp_shade", shade), pivot, {0, -1.2f, 0});
  // 10 W/sr at 2.2 m: 10 / 2.2^2 = 2.1 W/m^2 on the floor below.
  b.add_light_node("swinging_lamp", point_light(10.0f, {1.0f, 0.9f, 0.75f}, true), {0, -1.35f, 0},
                   glm::quat(1, 0, 0, 0), pivot);
}

void add_corridor_door(SceneBuilder& b, const DemoMaterials& m) {
  // The corridor's door (added last, so the other nodes keep their indices): a 4 cm leaf
  // filling the hub-corridor doorway (x [3.2, 4.8], y [0, 2.4]) on its corridor side
  // (z = 8.2), hinged at x = 3.2 about +y. Authored open: swung 90 degrees into the
  // corridor, against its west wall; rotation 0 closes it. Flagged gi.region "deforming":
  // antiradiance lights the change when the game (key O) swings it (docs/antiradiance.md).
  MeshBuilder door;
  door.box(m.wood, {0.8f, 1.19f, 0.02f}, {0.79f, 1.19f, 0.02f});
  const int door_node = b.add_mesh_node("corridor_door", door, engine::Mobility::Static, {3.2f, 0.0f, 8.2f},
                                        glm::angleAxis(glm::radians(-90.0f), glm::vec3(0, 1, 0)));
  b.asset().nodes[static_cast<std::size_t>(door_node)].gi.region = engine::GiRegion::Deforming;
}

// The textured extras added after the other nodes: the hub's rug and the crate room's grille.
void add_rug_and_grille(SceneBuilder& b) {
  // A 2 x 2 m tartan rug in the hub's south-east quarter, 4 mm above the floor (whole
  // repeats of the 1 m texture, so its border follows the sett).
  MeshBuilder rug;
  rug.horizontal(b.textured_material("rug_tartan", b.image(tartan_fabric_texture())), 0.004f, 5.0f, 7.0f, 2.0f, 4.0f,
                 1.0f);
  b.add_mesh_node("hub_rug", rug, engine::Mobility::Static);
  // A 0.6 m wire-mesh grille 0.5 m under the crate room's light (y 2.8, ceiling 3): its
  // shadow covers ~3.4 m of the floor with 35 cm diamonds. Double-sided: seen from below,
  // shadowing from above.
  const int mesh_mat = b.textured_material("wire_mesh", b.image(wire_mesh_texture()), 0.5f);
  engine::Material& wire = b.asset().materials[static_cast<std::size_t>(mesh_mat)];
  wire.alpha_mode = engine::AlphaMode::Mask;
  wire.alpha_cutoff = 0.5f;
  wire.double_sided = true;
  MeshBuilder grille;
  grille.horizontal(mesh_mat, 2.3f, 10.9f, 11.5f, 3.7f, 4.3f, -1.0f);
  b.add_mesh_node("crate_room_grille", grille, engine::Mobility::Static);
}

}  // namespace

engine::SceneAsset demo_level() {
  SceneBuilder b;
  const DemoMaterials m = demo_materials(b);
  add_hub(b, m);
  add_crate_room(b, m);
  add_corridor(b, m);
  add_lamp_room(b, m);
  b.add_camera_node("camera", {4.0f, 1.7f, 1.0f}, {4.0f, 1.3f, 8.0f}, glm::radians(65.0f));
  add_corridor_door(b, m);
  add_rug_and_grille(b);
  return b.take();
}

}  // namespace scenegen
