#pragma once
// Deterministic input scripts: an autopilot that plays the level like a person would
// (turning with the mouse, walking with W, pressing F, E and G), so headless runs and the
// committed sessions are input streams a command can reproduce.
//   game_demo::ScriptedPilot pilot(sim, game_demo::Script::Tour, 600);
//   for (int i = 0; i < 600; ++i) sim.step(pilot.next(sim));

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <game_demo/input_frame.h>
#include <game_demo/simulation.h>

namespace game_demo {

/// What a script does within its frame budget.
enum class Script : std::uint8_t {
  Tour,            ///< flashlight on, push the nearest crate, split screen on, walk the rooms
  WalkFlashlight,  ///< walk from room to room, flashlight on then off again
  PushCrates,      ///< walk to each crate in turn and push it
  SplitScreen,     ///< walk the rooms toggling the split screen on and off
  OpenDoor,        ///< stand at the start facing the corridor door: close it, then open it
  CrateToWall,     ///< push the red crate (else the first) toward the start until a wall stops it, then
                   ///< walk round to the wall's other side and look at it where the crate stands
  None,            ///< no input at all: the scene's own camera, still (gi_demo's default but on the demo level)
};

/// "tour", "walk_flashlight", "push_crates", "split_screen", "open_door", "crate_to_wall", "none".
std::optional<Script> script_from_name(std::string_view name);
std::string_view script_name(Script s);
/// gi_demo's script when --script is not given: Tour for the demo level (no --scene, or a
/// file named demo_level.*), None (the scene's own camera, still) for any other scene.
Script default_script(std::string_view scene_as_given);

class ScriptedPilot {
 public:
  /// Plans on the simulation's current state: a walkability grid (0.25 m cells) from the
  /// collision world at the camera's height, waypoints at the centres of large static
  /// meshes spanning eye height (rooms; the static lights when there are none) and crates. `frames` is the budget the
  /// timed key presses scale to.
  ScriptedPilot(const Simulation& sim, Script script, std::uint64_t frames);

  /// The input for the next step of `sim`.
  InputFrame next(const Simulation& sim);

  /// Waypoints (world, eye height) in visiting order; for tests and logs.
  const std::vector<glm::vec3>& waypoints() const { return waypoints_; }

 private:
  struct Cell {
    int x = 0, z = 0;
  };
  /// Marks the grid's cells where the (fattened) player box meets no wall and no crate, at
  /// the crates' current places.
  void mark_walkable(const Simulation& sim);
  /// The walkability grid over the level bounds at eye height, its cells coarsened until the
  /// walkability test stays cheap.
  void build_grid(const Simulation& sim, const glm::vec3& eye);
  /// The centres of large static meshes at eye height (rooms), else of the static lights,
  /// each reachable and 2 m or more from the others.
  std::vector<glm::vec3> room_points(const Simulation& sim, const glm::vec3& eye) const;
  /// The script's waypoints among the rooms and crates, and its key presses.
  void plan_script(const engine::Registry& reg, const glm::vec3& eye, const std::vector<glm::vec3>& rooms,
                   const std::vector<glm::vec3>& crates);
  bool walkable(int x, int z) const;
  std::optional<Cell> nearest_walkable(const glm::vec3& p) const;
  glm::vec3 cell_center(Cell c) const;
  std::vector<glm::vec3> find_path(const glm::vec3& from, const glm::vec3& to) const;
  void start_target(const Simulation& sim);
  /// CrateToWall's phases (see the enum); returns the input for this frame.
  void next_crate_to_wall(const Simulation& sim, InputFrame& in);
  /// Walks along path_ toward its end; true when there (within 0.3 m).
  bool follow_path(const glm::vec3& eye, float yaw_rad, float look_rad_per_px, InputFrame& in);

  Script script_;
  std::uint64_t budget_;
  std::uint64_t frame_ = 0;
  // Grid.
  glm::vec3 origin_{0.0f};
  float cell_m_ = 0.25f;
  int nx_ = 0, nz_ = 0;
  std::vector<std::uint8_t> free_;
  // Plan.
  std::vector<glm::vec3> waypoints_;
  std::vector<bool> waypoint_is_crate_;
  std::size_t next_waypoint_ = 0;
  std::vector<glm::vec3> path_;
  std::size_t path_index_ = 0;
  bool has_target_ = false;
  bool target_is_crate_ = false;
  glm::vec3 target_{0.0f};
  std::uint64_t target_frames_ = 0;
  std::uint64_t wait_until_ = 0;
  std::vector<std::uint64_t> key_presses_[kKeyCount];
  // CrateToWall: 0 walk behind the crate, 1 turn and push, 2 watch it slide, 3 walk to the
  // wall's other side, 4 look at the wall.
  int wall_phase_ = 0;
  engine::Entity wall_crate_;
  glm::vec3 wall_push_dir_{0.0f};
  glm::vec3 wall_crate_at_push_{0.0f};
  int wall_pushes_ = 0;
  float wanted_pitch_rad_ = -0.12f;  // look slightly down: floor, crates and walls in view
  std::uint64_t wall_phase_frames_ = 0;
};

}  // namespace game_demo
