#include <game_demo/gameplay.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/matrix_decompose.hpp>

#include <engine/components.h>
#include <engine/finite.h>

namespace game_demo {

namespace {

constexpr float kMaxPitchRad = 1.45f;
constexpr float kModelRadiusM = 2.5f;  // framing_view: a smaller bounding sphere is a model, not a level

glm::quat rotation_of(float yaw_rad, float pitch_rad) {
  return glm::angleAxis(yaw_rad, glm::vec3(0, 1, 0)) * glm::angleAxis(pitch_rad, glm::vec3(1, 0, 0));
}

Aabb player_box(const PlayerController& pc, const glm::vec3& eye) {
  return {eye + pc.box_min_from_eye_m, eye + pc.box_max_from_eye_m};
}

}  // namespace

std::vector<engine::Entity> crates_of(const engine::Registry& reg) {
  std::vector<engine::Entity> out;
  for (engine::Entity e : reg.view<engine::DynamicTag, engine::RigidBody, engine::Transform>().entities())
    if (!reg.get<engine::Transform>(e).parent) out.push_back(e);  // parts of rigs (lamp shade) are not crates
  return out;
}

namespace {

// True when moving `mover` from `from` to `to` newly enters another crate's box.
bool crate_blocks(const engine::Registry& reg, engine::Entity mover, const Aabb& from, const Aabb& to, float skin) {
  for (engine::Entity c : crates_of(reg)) {
    if (c == mover) continue;
    const Aabb b = crate_box(reg, c, skin);
    if (b.overlaps(to) && !b.overlaps(from)) return true;
  }
  return false;
}

// True when `to` leaves the level's horizontal bounds that `from` was inside.
bool leaves_bounds(const Aabb& level, const Aabb& from, const Aabb& to) {
  if (level.empty()) return false;
  auto inside = [&](const Aabb& b) {
    return b.min.x >= level.min.x && b.max.x <= level.max.x && b.min.z >= level.min.z && b.max.z <= level.max.z;
  };
  return inside(from) && !inside(to);
}

Aabb mesh_world_bounds(const engine::Scene& scene, engine::Entity e) {
  Aabb box{glm::vec3(std::numeric_limits<float>::max()), glm::vec3(std::numeric_limits<float>::lowest())};
  const auto* mr = scene.registry.try_get<engine::MeshRenderer>(e);
  const auto* wt = scene.registry.try_get<engine::WorldTransform>(e);
  if (!mr || !wt || mr->mesh >= scene.assets.meshes.size()) return box;
  for (const engine::Primitive& p : scene.assets.meshes[mr->mesh].primitives)
    for (const glm::vec3& v : p.positions) {
      const glm::vec3 w = glm::vec3(wt->matrix * glm::vec4(v, 1.0f));
      box.min = glm::min(box.min, w);
      box.max = glm::max(box.max, w);
    }
  return box;
}

// Flying: along the view (pitch included), sideways on the horizontal and along world +Y,
// at the scene's fly speed, through everything.
void fly(engine::Registry& reg, const engine::FrameTime& time, const GameplayContext& ctx, float fwd, float side,
         const glm::vec3& view, const glm::vec3& right) {
  const float vertical = (ctx.input.held(Key::Up) ? 1.0f : 0.0f) - (ctx.input.held(Key::Down) ? 1.0f : 0.0f);
  const glm::vec3 direction = view * fwd + right * side + glm::vec3(0.0f, vertical, 0.0f);
  if (direction == glm::vec3(0.0f)) return;
  const float speed = reg.get<PlayerController>(ctx.camera).fly_speed_m_s;
  const glm::vec3 step = glm::normalize(direction) * (speed * static_cast<float>(time.dt_s));
  if (engine::all_finite(step)) reg.write<engine::Transform>(ctx.camera).position += step;
}

void player_controller(engine::Registry& reg, const engine::FrameTime& time, GameplayContext& ctx) {
  if (!ctx.camera || !reg.has<PlayerController>(ctx.camera)) return;
  const InputFrame& in = ctx.input;
  const PlayerController& pc = reg.get<PlayerController>(ctx.camera);

  // Mouse look: only a real change of angle is written.
  float yaw = pc.yaw_rad - in.mouse_dx_px * pc.look_rad_per_px;
  float pitch = std::clamp(pc.pitch_rad - in.mouse_dy_px * pc.look_rad_per_px, -kMaxPitchRad, kMaxPitchRad);
  if (!std::isfinite(yaw) || !std::isfinite(pitch)) yaw = pc.yaw_rad, pitch = pc.pitch_rad;
  yaw = std::remainder(yaw, 2.0f * glm::pi<float>());
  if (yaw != pc.yaw_rad || pitch != pc.pitch_rad) {
    PlayerController& w = reg.write<PlayerController>(ctx.camera);
    w.yaw_rad = yaw;
    w.pitch_rad = pitch;
    reg.write<engine::Transform>(ctx.camera).rotation = rotation_of(yaw, pitch);
  }

  const float fwd = (in.held(Key::W) ? 1.0f : 0.0f) - (in.held(Key::S) ? 1.0f : 0.0f);
  const float side = (in.held(Key::D) ? 1.0f : 0.0f) - (in.held(Key::A) ? 1.0f : 0.0f);
  const glm::vec3 forward = forward_of_yaw(yaw);
  const glm::vec3 right(-forward.z, 0.0f, forward.x);
  if (ctx.tuning.locomotion == Locomotion::Fly) {
    fly(reg, time, ctx, fwd, side, rotation_of(yaw, pitch) * glm::vec3(0.0f, 0.0f, -1.0f), right);
    return;
  }
  // Walking: horizontal, one axis at a time so the player slides along walls.
  if (fwd == 0.0f && side == 0.0f) return;
  const glm::vec3 step =
      glm::normalize(forward * fwd + right * side) * (pc.walk_speed_m_s * static_cast<float>(time.dt_s));
  glm::vec3 eye = reg.get<engine::Transform>(ctx.camera).position;
  const glm::vec3 start = eye;
  for (int axis : {0, 2}) {
    if (step[axis] == 0.0f) continue;
    glm::vec3 next = eye;
    next[axis] += step[axis];
    const Aabb from = player_box(pc, eye), to = player_box(pc, next);
    if (ctx.collision.blocks_move(from, to) || leaves_bounds(ctx.collision.level_bounds(), from, to) ||
        crate_blocks(reg, engine::kNullEntity, from, to, 0.0f))
      continue;
    eye = next;
  }
  if (eye != start) reg.write<engine::Transform>(ctx.camera).position = eye;
}

void toggle_flashlight(engine::Registry& reg, GameplayContext& ctx) {
  if (!ctx.pressed(Key::F) || !ctx.flashlight || !reg.has<engine::Light>(ctx.flashlight)) return;
  engine::Light& light = reg.write<engine::Light>(ctx.flashlight);
  light.enabled = !light.enabled;
}

// O swings the door between its authored rotation and closed (rotation about its hinge,
// the node origin, to identity) at once.
void toggle_door(engine::Registry& reg, GameplayContext& ctx) {
  if (!ctx.pressed(Key::O) || !ctx.door || !reg.has<engine::Transform>(ctx.door)) return;
  ctx.door_closed = !ctx.door_closed;
  reg.write<engine::Transform>(ctx.door).rotation =
      ctx.door_closed ? glm::quat(1.0f, 0.0f, 0.0f, 0.0f) : ctx.door_open_rotation;
}

void push_crate(engine::Registry& reg, GameplayContext& ctx) {
  if (!ctx.pressed(Key::E) || !ctx.camera) return;
  const glm::vec3 eye = reg.get<engine::Transform>(ctx.camera).position;  // the player walks in world space
  const glm::vec3 view = forward_of_yaw(reg.get<PlayerController>(ctx.camera).yaw_rad);
  engine::Entity best;
  float best_d = std::numeric_limits<float>::max();
  for (engine::Entity c : crates_of(reg)) {
    const Aabb box = crate_box(reg, c, 0.0f);
    const glm::vec3 closest = glm::clamp(eye, box.min, box.max);
    const float d = glm::length(closest - eye);
    glm::vec3 to_center = box.center() - eye;
    to_center.y = 0.0f;
    const float len = glm::length(to_center);
    const bool in_front = len < 1e-4f || glm::dot(to_center / len, view) >= ctx.tuning.push_cone_cos;
    if (d <= ctx.tuning.push_reach_m && in_front && d < best_d) best_d = d, best = c;
  }
  if (!best) return;
  engine::RigidBody& rb = reg.write<engine::RigidBody>(best);
  rb.velocity_m_s += view * (ctx.tuning.push_impulse_n_s / std::max(rb.mass_kg, 1e-3f));
}

void swing_lamp(engine::Registry& reg, const engine::FrameTime& time, const GameplayContext& ctx) {
  if (!ctx.swinging_pivot) return;
  const double phase = 2.0 * 3.14159265358979 * time.time_s / double{ctx.tuning.lamp_period_s};
  const float angle = ctx.tuning.lamp_amplitude_rad * static_cast<float>(std::sin(phase));
  const glm::quat q = ctx.pivot_rest_rotation * glm::angleAxis(angle, glm::vec3(0, 0, 1));
  if (q != reg.get<engine::Transform>(ctx.swinging_pivot).rotation)
    reg.write<engine::Transform>(ctx.swinging_pivot).rotation = q;
}

// A crate rests on something when a box a few centimetres below it meets a floor or
// another crate it does not already overlap.
bool supported(const engine::Registry& reg, engine::Entity crate, const Aabb& box, const GameplayContext& ctx) {
  const Aabb probe = box.shifted({0.0f, -ctx.tuning.support_probe_m, 0.0f});
  return ctx.collision.blocks_vertical_move(box, probe) ||
         crate_blocks(reg, crate, box, probe, ctx.tuning.collision_skin_m);
}

void integrate_rigid_bodies(engine::Registry& reg, const engine::FrameTime& time, GameplayContext& ctx) {
  const float dt = static_cast<float>(time.dt_s);
  const float skin = ctx.tuning.collision_skin_m;
  for (engine::Entity c : crates_of(reg)) {
    const engine::RigidBody& rb = reg.get<engine::RigidBody>(c);
    const Aabb box0 = crate_box(reg, c, skin);
    glm::vec3 v = rb.velocity_m_s;
    const bool falling = !supported(reg, c, box0, ctx);
    if (v == glm::vec3(0.0f) && !falling) continue;  // at rest: nothing is written
    const float keep = std::pow(1.0f - std::clamp(rb.linear_damping, 0.0f, 1.0f), dt);
    v.x *= keep;
    v.z *= keep;
    if (falling) v.y -= ctx.tuning.gravity_m_s2 * dt;
    glm::vec3 pos = reg.get<engine::Transform>(c).position;
    const glm::vec3 start = pos;
    for (int axis : {1, 0, 2}) {
      if (v[axis] == 0.0f) continue;
      const Aabb from = box0.shifted(pos - start);
      const Aabb to = from.shifted(glm::vec3(axis == 0, axis == 1, axis == 2) * (v[axis] * dt));
      const bool wall = axis == 1 ? ctx.collision.blocks_vertical_move(from, to) : ctx.collision.blocks_move(from, to);
      if (wall || crate_blocks(reg, c, from, to, skin)) {
        v[axis] = 0.0f;  // hit a wall, the floor or another crate: stop along this axis
        continue;
      }
      pos[axis] += v[axis] * dt;
    }
    if (glm::length(glm::vec2(v.x, v.z)) < ctx.tuning.rest_speed_m_s) v.x = v.z = 0.0f;
    if (v != rb.velocity_m_s) reg.write<engine::RigidBody>(c).velocity_m_s = v;
    if (pos != start) reg.write<engine::Transform>(c).position = pos;
  }
}

}  // namespace

glm::vec3 forward_of_yaw(float yaw_rad) { return {-std::sin(yaw_rad), 0.0f, -std::cos(yaw_rad)}; }

Aabb crate_box(const engine::Registry& reg, engine::Entity crate, float skin_m) {
  const glm::vec3 pos = reg.get<engine::Transform>(crate).position;
  const glm::vec3 half = reg.get<engine::RigidBody>(crate).half_extents_m - glm::vec3(0.0f, skin_m, 0.0f);
  const auto* shape = reg.try_get<CrateShape>(crate);
  const glm::vec3 center = pos + (shape ? shape->center_offset_m : glm::vec3(0.0f));
  return {center - glm::max(half, glm::vec3(0.0f)), center + glm::max(half, glm::vec3(0.0f))};
}

Locomotion default_locomotion(std::string_view scene_as_given) {
  if (scene_as_given.empty()) return Locomotion::Walk;  // gi_demo's default scene: the demo level
  const std::string file = std::filesystem::path(scene_as_given).filename().string();
  return file.starts_with("demo_level.") ? Locomotion::Walk : Locomotion::Fly;
}

engine::Transform framing_view(const glm::vec3& min, const glm::vec3& max, engine::Camera& camera) {
  const glm::vec3 centre = 0.5f * (min + max);
  const float radius = 0.5f * glm::length(max - min);
  engine::Transform t;
  t.position = centre;
  if (!(radius > 0.0f) || !std::isfinite(radius)) return t;
  if (radius < kModelRadiusM) {  // a model: from the front, its sphere filling 1/1.6 of the view
    t.position = centre + glm::vec3(0.0f, 0.0f, 1.6f * radius / std::tan(0.5f * camera.yfov_rad));
    camera.znear_m = std::min(camera.znear_m, 0.1f * radius);
    return t;
  }
  // A level: from above a diagonal, the whole bounding sphere within the vertical field of view.
  const glm::vec3 from_centre = glm::normalize(glm::vec3(1.0f, 1.0f, 1.0f));
  const float distance = radius / std::sin(0.5f * camera.yfov_rad);
  t.position = centre + from_centre * distance;
  const glm::vec3 f = -from_centre;
  t.rotation = rotation_of(std::atan2(-f.x, -f.z), std::asin(f.y));
  camera.znear_m = 0.005f * radius;
  camera.zfar_m = 4.0f * (distance + radius);
  return t;
}

namespace {

// The player's camera: the one named "camera", else the first, else a new one framing the
// scene; unparented (the player moves it in world space), with its PlayerController.
engine::Entity prepare_player(engine::Scene& scene, const Aabb& bounds, const GameplayTuning& tuning) {
  engine::Registry& reg = scene.registry;
  engine::Entity player = engine::find_by_name(reg, "camera");
  if (!player || !reg.has<engine::Camera>(player)) player = engine::find_camera(reg);
  if (!player) {
    player = reg.create();
    reg.emplace<engine::Name>(player, engine::Name{"camera"});
    engine::Camera camera;
    reg.emplace<engine::Transform>(player,
                                   bounds.empty() ? engine::Transform{} : framing_view(bounds.min, bounds.max, camera));
    reg.emplace<engine::Camera>(player, camera);
  } else if (const engine::Transform& t = reg.get<engine::Transform>(player); t.parent) {
    // The player moves the camera in world space: a camera under a parent node starts at
    // its world pose, parented to nothing.
    glm::vec3 scale, skew;
    glm::vec4 perspective;
    engine::Transform world;
    glm::decompose(reg.get<engine::WorldTransform>(player).matrix, scale, world.rotation, world.position, skew,
                   perspective);
    world.rotation = glm::normalize(world.rotation);
    reg.write<engine::Transform>(player) = world;
    engine::update_world_transforms(reg);
  }
  const glm::quat q = reg.get<engine::Transform>(player).rotation;
  const glm::vec3 f = q * glm::vec3(0, 0, -1);
  PlayerController pc;
  pc.yaw_rad = std::atan2(-f.x, -f.z);
  pc.pitch_rad = std::asin(std::clamp(f.y, -1.0f, 1.0f));
  pc.fly_speed_m_s = bounds.empty() ? pc.walk_speed_m_s : glm::length(bounds.max - bounds.min) / tuning.fly_crossing_s;
  reg.emplace<PlayerController>(player, pc);
  return player;
}

// The flashlight: the scene's light named "flashlight" (made to move), else a new spot
// under the camera, off.
engine::Entity prepare_flashlight(engine::Registry& reg, engine::Entity camera) {
  engine::Entity light = engine::find_by_name(reg, "flashlight");
  if (!light || !reg.has<engine::Light>(light)) {
    light = reg.create();
    reg.emplace<engine::Name>(light, engine::Name{"flashlight"});
    reg.emplace<engine::Transform>(light, engine::Transform{.position = {0.15f, -0.15f, 0.0f}, .parent = camera});
    reg.emplace<engine::Light>(light, engine::Light{.type = engine::LightType::Spot,
                                                    .color = {1.0f, 0.93f, 0.82f},
                                                    .intensity = 4.0f,
                                                    .range_m = 20.0f,
                                                    .inner_cone_rad = 0.22f,
                                                    .outer_cone_rad = 0.42f,
                                                    .moves = true,
                                                    .cast_shadows = true,
                                                    .enabled = false});
  } else if (!reg.get<engine::Light>(light).moves) {
    reg.write<engine::Light>(light).moves = true;
  }
  return light;
}

}  // namespace

GameplayContext prepare_scene(engine::Scene& scene, const GameplayTuning& tuning) {
  engine::Registry& reg = scene.registry;
  engine::update_world_transforms(reg);
  GameplayContext ctx;
  ctx.tuning = tuning;
  ctx.collision = CollisionWorld::build(scene);
  Aabb bounds{glm::vec3(std::numeric_limits<float>::max()), glm::vec3(std::numeric_limits<float>::lowest())};
  for (engine::Entity e : reg.entities_with<engine::MeshRenderer>()) {
    const Aabb b = mesh_world_bounds(scene, e);
    if (b.empty()) continue;
    bounds.min = glm::min(bounds.min, b.min);
    bounds.max = glm::max(bounds.max, b.max);
  }

  ctx.camera = prepare_player(scene, bounds, tuning);
  ctx.flashlight = prepare_flashlight(reg, ctx.camera);

  // The swinging lamp's pivot (demo level), if the scene has one.
  ctx.swinging_pivot = engine::find_by_name(reg, "lamp_pivot");
  if (ctx.swinging_pivot && reg.has<engine::Transform>(ctx.swinging_pivot))
    ctx.pivot_rest_rotation = reg.get<engine::Transform>(ctx.swinging_pivot).rotation;
  else
    ctx.swinging_pivot = engine::kNullEntity;

  // The door: the demo level's corridor door, else the first mesh node flagged as a deforming
  // region (gi.region "deforming", e.g. corridor.gltf's "door"), if the scene has one.
  ctx.door = engine::find_by_name(reg, "corridor_door");
  for (std::size_t i = 0; !ctx.door && i < scene.assets.nodes.size() && i < scene.node_entities.size(); ++i)
    if (scene.assets.nodes[i].mesh >= 0 && scene.assets.nodes[i].gi.region == engine::GiRegion::Deforming)
      ctx.door = scene.node_entities[i];
  if (ctx.door && reg.has<engine::Transform>(ctx.door))
    ctx.door_open_rotation = reg.get<engine::Transform>(ctx.door).rotation;
  else
    ctx.door = engine::kNullEntity;

  // Crates: collision boxes from their meshes.
  for (engine::Entity c : crates_of(reg)) {
    const Aabb box = mesh_world_bounds(scene, c);
    if (box.empty()) continue;
    engine::RigidBody& rb = reg.write<engine::RigidBody>(c);
    rb.half_extents_m = 0.5f * (box.max - box.min);
    if (rb.linear_damping == 0.0f) rb.linear_damping = tuning.crate_damping;
    reg.emplace<CrateShape>(c, CrateShape{box.center() - reg.get<engine::Transform>(c).position});
  }
  engine::update_world_transforms(reg);
  return ctx;
}

void add_gameplay_systems(engine::SystemSchedule& schedule, GameplayContext& ctx) {
  GameplayContext* c = &ctx;
  schedule.add(engine::Stage::Input, "player_controller",
               [c](engine::Registry& r, const engine::FrameTime& t) { player_controller(r, t, *c); });
  schedule.add(engine::Stage::Gameplay, "flashlight",
               [c](engine::Registry& r, const engine::FrameTime&) { toggle_flashlight(r, *c); });
  schedule.add(engine::Stage::Gameplay, "split_screen", [c](engine::Registry&, const engine::FrameTime&) {
    if (c->pressed(Key::G)) c->split_view = !c->split_view;
  });
  schedule.add(engine::Stage::Gameplay, "push",
               [c](engine::Registry& r, const engine::FrameTime&) { push_crate(r, *c); });
  schedule.add(engine::Stage::Gameplay, "swinging_lamp",
               [c](engine::Registry& r, const engine::FrameTime& t) { swing_lamp(r, t, *c); });
  schedule.add(engine::Stage::Gameplay, "door",
               [c](engine::Registry& r, const engine::FrameTime&) { toggle_door(r, *c); });
  schedule.add(engine::Stage::Physics, "rigid_bodies",
               [c](engine::Registry& r, const engine::FrameTime& t) { integrate_rigid_bodies(r, t, *c); });
  schedule.add(engine::Stage::Transform, "world_transforms",
               [](engine::Registry& r, const engine::FrameTime&) { engine::update_world_transforms(r); });
}

}  // namespace game_demo
