#include <game_demo/state_checksum.h>

#include <engine/components.h>

#include <game_demo/gameplay.h>

namespace game_demo {

std::uint64_t state_checksum(const engine::Registry& reg, const ChecksumExtras& extras) {
  Fnv1a64 h;
  h.u64(extras.frame);
  h.u64(extras.seed);
  h.u32(extras.previous_keys);
  h.byte(extras.split_view ? 1 : 0);
  for (engine::Entity e : reg.entities_with<engine::Transform>()) {
    h.u64(e.id());
    const engine::Transform& t = reg.get<engine::Transform>(e);
    h.vec3(t.position);
    h.quat(t.rotation);
    h.vec3(t.scale);
    h.u64(t.parent.id());
    if (const auto* rb = reg.try_get<engine::RigidBody>(e)) {
      h.byte('R');
      h.vec3(rb->velocity_m_s);
      h.f32(rb->mass_kg);
      h.f32(rb->linear_damping);
      h.vec3(rb->half_extents_m);
    }
    if (const auto* light = reg.try_get<engine::Light>(e)) {
      h.byte('L');
      h.byte(light->enabled ? 1 : 0);
      h.byte(light->moves ? 1 : 0);
    }
    if (const auto* cam = reg.try_get<engine::Camera>(e)) {
      h.byte('C');
      h.f32(cam->yfov_rad);
      h.f32(cam->znear_m);
      h.f32(cam->zfar_m);
      h.f32(cam->aspect);
    }
    if (const auto* pc = reg.try_get<PlayerController>(e)) {
      h.byte('P');
      h.f32(pc->yaw_rad);
      h.f32(pc->pitch_rad);
    }
  }
  return h.value();
}

}  // namespace game_demo
