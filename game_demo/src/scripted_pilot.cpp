#include <game_demo/scripted_pilot.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <limits>

#include <engine/components.h>

namespace game_demo {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr std::uint64_t kGiveUpFrames = 60 * 25;
constexpr std::uint64_t kStuckFrames = 45;

float wrap_angle(float a) { return std::remainder(a, 2.0f * kPi); }

float yaw_towards(const glm::vec3& from, const glm::vec3& to) {
  const glm::vec3 d = to - from;
  return std::atan2(-d.x, -d.z);
}

float horizontal_distance(const glm::vec3& a, const glm::vec3& b) {
  return glm::length(glm::vec2(a.x - b.x, a.z - b.z));
}

// Greedy nearest-neighbour order starting at `from`.
std::vector<std::size_t> visiting_order(const glm::vec3& from, const std::vector<glm::vec3>& points) {
  std::vector<std::size_t> order;
  std::vector<bool> used(points.size(), false);
  glm::vec3 at = from;
  for (std::size_t n = 0; n < points.size(); ++n) {
    std::size_t best = 0;
    float best_d = std::numeric_limits<float>::max();
    for (std::size_t i = 0; i < points.size(); ++i)
      if (!used[i] && horizontal_distance(at, points[i]) < best_d)
        best_d = horizontal_distance(at, points[i]), best = i;
    used[best] = true;
    order.push_back(best);
    at = points[best];
  }
  return order;
}

}  // namespace

std::optional<Script> script_from_name(std::string_view name) {
  for (Script s : {Script::Tour, Script::WalkFlashlight, Script::PushCrates, Script::SplitScreen, Script::OpenDoor,
                   Script::CrateToWall, Script::None})
    if (script_name(s) == name) return s;
  return std::nullopt;
}

Script default_script(std::string_view scene_as_given) {
  if (scene_as_given.empty()) return Script::Tour;
  const std::string file = std::filesystem::path(scene_as_given).filename().string();
  return file.starts_with("demo_level.") ? Script::Tour : Script::None;
}

std::string_view script_name(Script s) {
  switch (s) {
    case Script::Tour:
      return "tour";
    case Script::WalkFlashlight:
      return "walk_flashlight";
    case Script::PushCrates:
      return "push_crates";
    case Script::SplitScreen:
      return "split_screen";
    case Script::OpenDoor:
      return "open_door";
    case Script::CrateToWall:
      return "crate_to_wall";
    case Script::None:
      return "none";
  }
  return "?";
}

ScriptedPilot::ScriptedPilot(const Simulation& sim, Script script, std::uint64_t frames)
    : script_(script), budget_(frames) {
  const engine::Registry& reg = sim.registry();
  const glm::vec3 eye = reg.get<engine::Transform>(sim.context().camera).position;
  build_grid(sim, eye);
  // Waypoints: the centres of large static meshes at eye height (rooms), then crates.
  const std::vector<glm::vec3> rooms = room_points(sim, eye);
  std::vector<glm::vec3> crates;
  for (engine::Entity c : crates_of(reg)) {
    glm::vec3 p = crate_box(reg, c, 0.0f).center();
    p.y = eye.y;
    crates.push_back(p);
  }
  plan_script(reg, eye, rooms, crates);
}

void ScriptedPilot::build_grid(const Simulation& sim, const glm::vec3& eye) {
  const GameplayContext& ctx = sim.context();
  const Aabb& level = ctx.collision.level_bounds();
  if (level.empty()) return;
  const double walls = static_cast<double>(std::max<std::size_t>(ctx.collision.wall_triangle_count(), 1));
  auto cells_at = [&](double c) {
    return (static_cast<double>(level.max.x - level.min.x) / c + 1.0) *
           (static_cast<double>(level.max.z - level.min.z) / c + 1.0);
  };
  while (cells_at(double{cell_m_}) * walls > 2e8 || cells_at(double{cell_m_}) > 4e6) cell_m_ *= 2.0f;
  origin_ = glm::vec3(level.min.x, eye.y, level.min.z);
  nx_ = static_cast<int>(std::ceil((level.max.x - level.min.x) / cell_m_)) + 1;
  nz_ = static_cast<int>(std::ceil((level.max.z - level.min.z) / cell_m_)) + 1;
  mark_walkable(sim);
}

std::vector<glm::vec3> ScriptedPilot::room_points(const Simulation& sim, const glm::vec3& eye) const {
  const engine::Registry& reg = sim.registry();
  std::vector<glm::vec3> rooms;
  for (engine::Entity e : reg.view<engine::MeshRenderer, engine::StaticTag, engine::WorldTransform>().entities()) {
    const std::uint32_t mesh = reg.get<engine::MeshRenderer>(e).mesh;
    if (mesh >= sim.scene().assets.meshes.size()) continue;
    Aabb b{glm::vec3(std::numeric_limits<float>::max()), glm::vec3(std::numeric_limits<float>::lowest())};
    const glm::mat4& m = reg.get<engine::WorldTransform>(e).matrix;
    for (const engine::Primitive& prim : sim.scene().assets.meshes[mesh].primitives)
      for (const glm::vec3& v : prim.positions) {
        const glm::vec3 w(m * glm::vec4(v, 1.0f));
        b.min = glm::min(b.min, w);
        b.max = glm::max(b.max, w);
      }
    if (b.empty() || (b.max.x - b.min.x) * (b.max.z - b.min.z) < 6.0f || !(b.min.y < eye.y && b.max.y > eye.y))
      continue;
    glm::vec3 p = b.center();
    p.y = eye.y;
    const bool near_other =
        std::any_of(rooms.begin(), rooms.end(), [&](const glm::vec3& r) { return horizontal_distance(r, p) < 2.0f; });
    if (!near_other && nearest_walkable(p)) rooms.push_back(p);
  }
  // Fallback for levels without room meshes: the static lights.
  const bool had_rooms = !rooms.empty();
  for (engine::Entity e : reg.view<engine::Light, engine::WorldTransform>().entities()) {
    const engine::Light& l = reg.get<engine::Light>(e);
    if (had_rooms || l.moves || l.type == engine::LightType::Directional || e == sim.context().flashlight) continue;
    glm::vec3 p = glm::vec3(reg.get<engine::WorldTransform>(e).matrix[3]);
    p.y = eye.y;
    const bool near_other =
        std::any_of(rooms.begin(), rooms.end(), [&](const glm::vec3& r) { return horizontal_distance(r, p) < 2.0f; });
    if (!near_other && nearest_walkable(p)) rooms.push_back(p);
  }
  return rooms;
}

void ScriptedPilot::plan_script(const engine::Registry& reg, const glm::vec3& eye, const std::vector<glm::vec3>& rooms,
                                const std::vector<glm::vec3>& crates) {
  auto add = [&](const std::vector<glm::vec3>& pts, bool is_crate, std::size_t limit) {
    const glm::vec3 from = waypoints_.empty() ? eye : waypoints_.back();
    for (std::size_t i : visiting_order(from, pts)) {
      if (limit-- == 0) break;
      waypoints_.push_back(pts[i]);
      waypoint_is_crate_.push_back(is_crate);
    }
  };
  const std::uint64_t n = budget_;
  switch (script_) {
    case Script::Tour:
      add(crates, true, 1);
      add(rooms, false, rooms.size());
      key_presses_[static_cast<int>(Key::F)] = {10};
      key_presses_[static_cast<int>(Key::G)] = {n / 2};
      break;
    case Script::WalkFlashlight:
      add(rooms, false, rooms.size());
      key_presses_[static_cast<int>(Key::F)] = {15, 2 * n / 3};
      break;
    case Script::PushCrates:
      add(crates, true, crates.size());
      break;
    case Script::SplitScreen:
      add(rooms, false, rooms.size());
      key_presses_[static_cast<int>(Key::G)] = {20, n / 2, 3 * n / 4};
      break;
    case Script::OpenDoor:  // no waypoints: the start faces the door
      key_presses_[static_cast<int>(Key::O)] = {n / 5, 5 * n / 8};
      break;
    case Script::CrateToWall: {  // no waypoints: next_crate_to_wall plans on the live crate
      const std::vector<engine::Entity> all = crates_of(reg);
      for (engine::Entity c : all)
        if (reg.has<engine::Name>(c) && reg.get<engine::Name>(c).value == "crate_red") wall_crate_ = c;
      if (!wall_crate_ && !all.empty()) wall_crate_ = all.front();
      if (wall_crate_) {
        glm::vec3 d = eye - crate_box(reg, wall_crate_, 0.0f).center();
        d.y = 0.0f;
        wall_push_dir_ = glm::length(d) > 1e-4f ? glm::normalize(d) : glm::vec3(-1, 0, 0);
      }
      break;
    }
    case Script::None:  // no waypoints, no keys
      break;
  }
}

bool ScriptedPilot::follow_path(const glm::vec3& eye, float yaw_rad, float look_rad_per_px, InputFrame& in) {
  if (path_.empty()) return true;
  std::size_t best = path_index_;
  float best_d = std::numeric_limits<float>::max();
  for (std::size_t k = path_index_; k < std::min(path_.size(), path_index_ + 12); ++k)
    if (horizontal_distance(eye, path_[k]) < best_d) best_d = horizontal_distance(eye, path_[k]), best = k;
  path_index_ = best;
  std::size_t aim_index = path_index_;
  while (aim_index + 1 < path_.size() && horizontal_distance(eye, path_[aim_index]) < 0.75f) ++aim_index;
  const glm::vec3 aim = aim_index + 1 >= path_.size() ? path_.back() : path_[aim_index];
  if (aim_index + 1 >= path_.size() && horizontal_distance(eye, path_.back()) < 0.3f) return true;
  const float err = wrap_angle(yaw_towards(eye, aim) - yaw_rad);
  in.mouse_dx_px = std::clamp(-err / look_rad_per_px * 0.2f, -14.0f, 14.0f);
  if (std::abs(in.mouse_dx_px) < 0.05f) in.mouse_dx_px = 0.0f;
  if (std::abs(err) < 0.5f) in.keys |= key_bit(Key::W);
  return false;
}

// Push the crate along wall_push_dir_ (toward where the player started) until a push moves
// it less than 5 cm or more than 15 degrees off the push (a wall stopped it or it slid along
// one), at most six times; then walk to 2.8 m past the crate
// along the push (the wall's other side) and look back and down at the crate through the wall.
// Long because it is one state machine: its five phases share the eye, the crate and the
// turn_to/go helpers over them, and read best as one switch.
void ScriptedPilot::next_crate_to_wall(const Simulation& sim, InputFrame& in) {
  const engine::Registry& reg = sim.registry();
  if (!wall_crate_) return;
  const PlayerController& pc = reg.get<PlayerController>(sim.context().camera);
  const glm::vec3 eye = reg.get<engine::Transform>(sim.context().camera).position;
  glm::vec3 crate = crate_box(reg, wall_crate_, 0.0f).center();
  crate.y = eye.y;
  ++wall_phase_frames_;
  auto turn_to = [&](float yaw) {
    const float err = wrap_angle(yaw - pc.yaw_rad);
    in.mouse_dx_px = std::clamp(-err / pc.look_rad_per_px * 0.2f, -14.0f, 14.0f);
    if (std::abs(in.mouse_dx_px) < 0.05f) in.mouse_dx_px = 0.0f;
    return std::abs(err);
  };
  auto go = [&](int phase, std::optional<glm::vec3> to) {
    if (to) mark_walkable(sim);  // the crates have moved since the grid was made
    wall_phase_ = phase;
    wall_phase_frames_ = 0;
    path_ = to ? find_path(eye, *to) : std::vector<glm::vec3>{};
    path_index_ = 0;
  };
  const float push_yaw = yaw_towards(glm::vec3(0.0f), wall_push_dir_);
  switch (wall_phase_) {
    case 0:  // walk behind the crate
      if (wall_phase_frames_ == 1) {
        mark_walkable(sim);
        path_ = find_path(eye, crate - wall_push_dir_ * 1.1f);
        path_index_ = 0;
      }
      if (follow_path(eye, pc.yaw_rad, pc.look_rad_per_px, in) || wall_phase_frames_ > kGiveUpFrames)
        go(1, std::nullopt);
      break;
    case 1:  // face along the push and push
      if (turn_to(push_yaw) < 0.03f) {
        in.keys |= key_bit(Key::E);
        wall_crate_at_push_ = crate;
        ++wall_pushes_;
        go(2, std::nullopt);
      }
      break;
    case 2:  // watch it slide to rest
      if (wall_phase_frames_ < 90) break;
      // Free: the crate went on along the push. Blocked (a wall): it stopped or slid aside.
      if (const glm::vec3 moved = crate - wall_crate_at_push_;
          glm::length(moved) > 0.05f && glm::dot(glm::normalize(moved), wall_push_dir_) > 0.966f && wall_pushes_ < 6) {
        go(0, std::nullopt);
      } else {
        go(3, crate + wall_push_dir_ * 2.8f);
      }
      break;
    case 3:  // the wall's other side
      if (follow_path(eye, pc.yaw_rad, pc.look_rad_per_px, in) || wall_phase_frames_ > kGiveUpFrames)
        go(4, std::nullopt);
      break;
    default: {  // look at the crate's place through the wall, down to the floor where it stands
      turn_to(yaw_towards(eye, crate));
      const glm::vec3 bottom = crate_box(reg, wall_crate_, 0.0f).center();
      wanted_pitch_rad_ = std::atan2(bottom.y - eye.y, std::max(horizontal_distance(eye, crate), 0.5f));
      break;
    }
  }
}

void ScriptedPilot::mark_walkable(const Simulation& sim) {
  const engine::Registry& reg = sim.registry();
  const GameplayContext& ctx = sim.context();
  const PlayerController& pc = reg.get<PlayerController>(ctx.camera);
  const Aabb& level = ctx.collision.level_bounds();
  free_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(nz_), 0);
  std::vector<Aabb> crates;
  for (engine::Entity c : crates_of(reg)) crates.push_back(crate_box(reg, c, 0.0f));
  for (int z = 0; z < nz_; ++z)
    for (int x = 0; x < nx_; ++x) {
      const glm::vec3 p = cell_center({x, z});
      // A slightly fattened player box keeps the walk off the walls.
      const Aabb box{p + pc.box_min_from_eye_m - glm::vec3(0.1f, 0, 0.1f),
                     p + pc.box_max_from_eye_m + glm::vec3(0.1f, 0, 0.1f)};
      bool ok = box.min.x >= level.min.x && box.max.x <= level.max.x && box.min.z >= level.min.z &&
                box.max.z <= level.max.z && !ctx.collision.overlaps_wall(box);
      for (const Aabb& c : crates) ok = ok && !c.overlaps(box);
      free_[static_cast<std::size_t>(z) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x)] = ok ? 1 : 0;
    }
}

bool ScriptedPilot::walkable(int x, int z) const {
  return x >= 0 && z >= 0 && x < nx_ && z < nz_ &&
         free_[static_cast<std::size_t>(z) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x)] != 0;
}

glm::vec3 ScriptedPilot::cell_center(Cell c) const {
  return origin_ +
         glm::vec3((static_cast<float>(c.x) + 0.5f) * cell_m_, 0.0f, (static_cast<float>(c.z) + 0.5f) * cell_m_);
}

std::optional<ScriptedPilot::Cell> ScriptedPilot::nearest_walkable(const glm::vec3& p) const {
  if (nx_ == 0) return std::nullopt;
  const int cx = static_cast<int>(std::floor((p.x - origin_.x) / cell_m_));
  const int cz = static_cast<int>(std::floor((p.z - origin_.z) / cell_m_));
  const int max_ring = static_cast<int>(std::ceil(3.0f / cell_m_));
  for (int ring = 0; ring <= max_ring; ++ring) {
    std::optional<Cell> best;
    float best_d = std::numeric_limits<float>::max();
    for (int dz = -ring; dz <= ring; ++dz)
      for (int dx = -ring; dx <= ring; ++dx) {
        if (std::max(std::abs(dx), std::abs(dz)) != ring || !walkable(cx + dx, cz + dz)) continue;
        const float d = horizontal_distance(cell_center({cx + dx, cz + dz}), p);
        if (d < best_d) best_d = d, best = Cell{cx + dx, cz + dz};
      }
    if (best) return best;
  }
  return std::nullopt;
}

std::vector<glm::vec3> ScriptedPilot::find_path(const glm::vec3& from, const glm::vec3& to) const {
  const std::optional<Cell> start = nearest_walkable(from), goal = nearest_walkable(to);
  if (!start || !goal) return {};
  const auto index = [&](Cell c) {
    return static_cast<std::size_t>(c.z) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(c.x);
  };
  std::vector<std::int32_t> came_from(free_.size(), -1);
  std::deque<Cell> queue{*start};
  came_from[index(*start)] = static_cast<std::int32_t>(index(*start));
  while (!queue.empty()) {
    const Cell c = queue.front();
    queue.pop_front();
    if (c.x == goal->x && c.z == goal->z) break;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dz == 0) || !walkable(c.x + dx, c.z + dz)) continue;
        if (dx != 0 && dz != 0 && (!walkable(c.x + dx, c.z) || !walkable(c.x, c.z + dz)))
          continue;  // no corner cutting
        const Cell n{c.x + dx, c.z + dz};
        if (came_from[index(n)] >= 0) continue;
        came_from[index(n)] = static_cast<std::int32_t>(index(c));
        queue.push_back(n);
      }
  }
  if (came_from[index(*goal)] < 0) return {};
  std::vector<glm::vec3> path;
  for (std::size_t i = index(*goal);; i = static_cast<std::size_t>(came_from[i])) {
    path.push_back(cell_center(
        {static_cast<int>(i % static_cast<std::size_t>(nx_)), static_cast<int>(i / static_cast<std::size_t>(nx_))}));
    if (i == index(*start)) break;
  }
  std::reverse(path.begin(), path.end());
  return path;
}

void ScriptedPilot::start_target(const Simulation& sim) {
  const glm::vec3 eye = sim.registry().get<engine::Transform>(sim.context().camera).position;
  for (std::size_t tries = 0; tries < waypoints_.size() && !has_target_; ++tries) {
    const std::size_t i = next_waypoint_ % waypoints_.size();
    ++next_waypoint_;
    // Pushed crates have moved: aim for where they are now.
    target_ = waypoints_[i];
    target_is_crate_ = waypoint_is_crate_[i];
    if (target_is_crate_ && next_waypoint_ > waypoints_.size()) continue;  // each crate is pushed once
    path_ = find_path(eye, target_);
    path_index_ = 0;
    target_frames_ = 0;
    has_target_ = !path_.empty();
  }
}

InputFrame ScriptedPilot::next(const Simulation& sim) {
  frame_ = sim.frame();
  InputFrame in;
  if (script_ == Script::None) return in;  // not even the pitch levelling: the scene's camera as authored
  for (int k = 0; k < kKeyCount; ++k)
    if (std::find(key_presses_[k].begin(), key_presses_[k].end(), frame_) != key_presses_[k].end())
      in.keys |= key_bit(static_cast<Key>(k));

  const engine::Registry& reg = sim.registry();
  const PlayerController& pc = reg.get<PlayerController>(sim.context().camera);
  const glm::vec3 eye = reg.get<engine::Transform>(sim.context().camera).position;
  in.mouse_dy_px = std::clamp(-(wanted_pitch_rad_ - pc.pitch_rad) / pc.look_rad_per_px * 0.1f, -6.0f, 6.0f);
  if (std::abs(in.mouse_dy_px) < 0.05f) in.mouse_dy_px = 0.0f;
  if (script_ == Script::CrateToWall) {
    next_crate_to_wall(sim, in);
    return in;
  }
  if (frame_ < wait_until_ || waypoints_.empty()) return in;
  if (!has_target_) start_target(sim);
  if (!has_target_) return in;

  // Follow the path: find the path cell nearest to the player (searching a little ahead of
  // the last one), then aim at the first cell at least 0.75 m away.
  {
    std::size_t best = path_index_;
    float best_d = std::numeric_limits<float>::max();
    for (std::size_t k = path_index_; k < std::min(path_.size(), path_index_ + 12); ++k)
      if (horizontal_distance(eye, path_[k]) < best_d) best_d = horizontal_distance(eye, path_[k]), best = k;
    path_index_ = best;
  }
  std::size_t aim_index = path_index_;
  while (aim_index + 1 < path_.size() && horizontal_distance(eye, path_[aim_index]) < 0.75f) ++aim_index;
  glm::vec3 aim = path_[aim_index];
  const bool at_end = aim_index + 1 >= path_.size() && horizontal_distance(eye, path_.back()) < 0.3f;
  bool push_now = false;
  if (target_is_crate_) {
    const float reach = sim.context().tuning.push_reach_m * 0.6f;
    if (horizontal_distance(eye, target_) < reach + 0.4f || at_end) {
      aim = target_;
      push_now = std::abs(wrap_angle(yaw_towards(eye, aim) - pc.yaw_rad)) < 0.1f;
    }
  }
  const float err = horizontal_distance(eye, aim) < 1e-3f ? 0.0f : wrap_angle(yaw_towards(eye, aim) - pc.yaw_rad);
  in.mouse_dx_px = std::clamp(-err / pc.look_rad_per_px * 0.2f, -14.0f, 14.0f);
  if (std::abs(in.mouse_dx_px) < 0.05f) in.mouse_dx_px = 0.0f;
  const bool close_to_crate = target_is_crate_ && aim == target_;
  if (std::abs(err) < 0.5f && !close_to_crate && !at_end) in.keys |= key_bit(Key::W);

  ++target_frames_;
  if (push_now) {
    in.keys |= key_bit(Key::E);
    has_target_ = false;
    wait_until_ = frame_ + 50;  // watch the crate slide
  } else if ((at_end && !target_is_crate_) || target_frames_ > kGiveUpFrames ||
             (close_to_crate && target_frames_ > kStuckFrames * 4 && std::abs(err) < 0.1f)) {
    has_target_ = false;
  }
  return in;
}

}  // namespace game_demo
