#pragma once
// The demo's gameplay: components the demo adds to a scene, and the systems that move the
// player, switch the flashlight, push crates and integrate their motion.
//   game_demo::GameplayContext ctx = game_demo::prepare_scene(scene);
//   game_demo::add_gameplay_systems(schedule, ctx);   // then schedule.run(...) every fixed step

#include <cstdint>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <engine/scene.h>
#include <engine/system_schedule.h>

#include <game_demo/collision_world.h>
#include <game_demo/input_frame.h>

namespace game_demo {

/// How the player moves (GameplayTuning::locomotion).
enum class Locomotion : std::uint8_t {
  Walk,  ///< W/A/S/D on the horizontal, blocked by walls, crates and the level's bounds (the demo level).
  Fly,   ///< W/S along the view (pitch included), A/D sideways, Up/Down along world +Y; no collision.
};

/// Walk on the demo level (a file named demo_level.*), Fly on any other scene: a level
/// nobody made for this demo's walking (no floors at eye height, no collision meshes) or a
/// single model is looked at from anywhere.
Locomotion default_locomotion(std::string_view scene_as_given);

/// First-person control state of the camera entity. The camera's rotation is
/// yaw (about world +Y) then pitch (about local +X), both in radians.
struct PlayerController {
  float yaw_rad = 0.0f;
  float pitch_rad = 0.0f;
  float walk_speed_m_s = 3.0f;
  /// Locomotion::Fly: the diagonal of the scene's bounds / GameplayTuning::fly_crossing_s,
  /// set by prepare_scene (walk_speed_m_s when the scene has no mesh).
  float fly_speed_m_s = 3.0f;
  float look_rad_per_px = 0.0025f;
  /// The player's collision box relative to the eye (camera position), metres.
  glm::vec3 box_min_from_eye_m{-0.25f, -1.2f, -0.25f};
  glm::vec3 box_max_from_eye_m{0.25f, 0.1f, 0.25f};
};

/// Collision box of a pushable rigid body: world-space AABB centre relative to the
/// entity's position (RigidBody::half_extents_m gives the size).
struct CrateShape {
  glm::vec3 center_offset_m{0.0f};
};

/// Gameplay tuning constants.
struct GameplayTuning {
  float push_reach_m = 2.0f;                 ///< Farthest crate surface the push reaches.
  float push_cone_cos = 0.5f;                ///< Crate centre within 60 degrees of the view direction.
  float push_impulse_n_s = 3.0f;             ///< Impulse along the horizontal view direction.
  float crate_damping = 0.9f;                ///< Fraction of crate velocity lost per second.
  float rest_speed_m_s = 0.05f;              ///< Below this a crate stops exactly.
  float gravity_m_s2 = 9.81f;                ///< Unsupported crates fall.
  float support_probe_m = 0.03f;             ///< How far below a crate support is looked for.
  float lamp_period_s = 3.2f;                ///< Swing period of the pivot named "lamp_pivot".
  float lamp_amplitude_rad = 0.35f;          ///< Swing amplitude about the pivot's local Z.
  float collision_skin_m = 0.01f;            ///< Crate boxes are shrunk vertically by this (resting contact).
  Locomotion locomotion = Locomotion::Walk;  ///< default_locomotion() of the scene in gi_demo.
  /// Locomotion::Fly: seconds to fly the diagonal of the scene's bounds, whatever its size
  /// (Dabrovic Sponza's bounds, 45 m across: 4.5 m/s).
  float fly_crossing_s = 10.0f;
};

/// The entities and shared data the systems work on, owned by the caller (Simulation);
/// the systems keep a pointer to it, so it must outlive the schedule.
struct GameplayContext {
  engine::Entity camera;
  engine::Entity flashlight;
  engine::Entity swinging_pivot;  ///< "lamp_pivot" when the scene has one, else null.
  glm::quat pivot_rest_rotation{1.0f, 0.0f, 0.0f, 0.0f};
  CollisionWorld collision;
  GameplayTuning tuning;
  InputFrame input;                 ///< This step's input (set before each run).
  std::uint32_t previous_keys = 0;  ///< Last step's held keys.
  bool split_view = false;          ///< Toggled by G; the renderer reads it.
  /// "corridor_door" when the scene has one, else its first mesh node flagged gi.region
  /// "deforming" (corridor.gltf's "door"), else null.
  engine::Entity door;
  glm::quat door_open_rotation{1.0f, 0.0f, 0.0f, 0.0f};  ///< Its authored (open) rotation; closed is identity.
  bool door_closed = false;                              ///< Toggled by O.

  bool pressed(Key k) const { return input.held(k) && (previous_keys & key_bit(k)) == 0; }
};

/// Readies an instantiated scene for play: finds the camera (the node named "camera", else
/// engine::find_camera's first camera in the file's node order; a camera under a parent node
/// is moved to the world at its world pose), or creates one that frames the bounds of the
/// scene's meshes (framing_view), adds its PlayerController (fly speed from those bounds), adds a flashlight (a Spot
/// light child of the camera, moves = true, switched off) unless a Light entity named "flashlight" exists, gives each
/// DynamicTag RigidBody a CrateShape and half extents from its mesh bounds, and builds the static collision world;
/// finds the door ("corridor_door" or the first deforming region's mesh, hinged at its origin; O swings it between its
/// authored rotation and closed). Leaves world transforms up to date. The collision world keeps the door where it was
/// authored (open).
GameplayContext prepare_scene(engine::Scene& scene, const GameplayTuning& tuning = {});

/// The view prepare_scene gives a scene without a camera, framing the world-space box
/// `min`..`max` of its meshes with `camera`'s vertical field of view: a model (bounding
/// sphere radius under 2.5 m) from the front (+Z, where glTF models face), its sphere
/// filling 1/1.6 of the view, znear at most a tenth of its radius; a level from above a
/// diagonal (direction (1, 1, 1) from the centre, 35 degrees up) looking at the centre with
/// the whole bounding sphere in view, znear 0.005 x radius and zfar 4 x (distance + radius)
/// so the player can fly out and still see it. Returns the transform; adjusts `camera`.
engine::Transform framing_view(const glm::vec3& min, const glm::vec3& max, engine::Camera& camera);

/// Adds, in this order: player_controller (Input), flashlight, split_screen, push,
/// swinging_lamp and door (Gameplay), rigid_bodies (Physics), world_transforms (Transform).
void add_gameplay_systems(engine::SystemSchedule& schedule, GameplayContext& context);

/// The pushable crates: root entities with DynamicTag, RigidBody and Transform.
std::vector<engine::Entity> crates_of(const engine::Registry& registry);

/// World-space collision box of a crate entity (shrunk vertically by `skin_m`).
Aabb crate_box(const engine::Registry& registry, engine::Entity crate, float skin_m);

/// Horizontal view direction of a yaw angle (unit length).
glm::vec3 forward_of_yaw(float yaw_rad);

}  // namespace game_demo
