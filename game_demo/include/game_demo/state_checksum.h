#pragma once
// A deterministic 64-bit fingerprint of the simulation state, compared frame by frame when
// a recorded session is replayed.
//   game_demo::Fnv1a64 h;  h.u64(frame);  h.f32(x);  std::uint64_t v = h.value();
//   std::uint64_t c = game_demo::state_checksum(registry, {.frame = 12});

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <engine/registry.h>

namespace game_demo {

/// FNV-1a, 64 bit, over exact bytes; multi-byte values are fed little-endian and floats by
/// their bit pattern, so equal states give equal hashes on every run and build.
class Fnv1a64 {
 public:
  void byte(std::uint8_t b) {
    h_ ^= b;
    h_ *= 0x100000001b3ull;
  }
  void bytes(std::span<const std::uint8_t> data) {
    for (std::uint8_t b : data) byte(b);
  }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) byte(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) byte(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void vec3(const glm::vec3& v) {
    f32(v.x);
    f32(v.y);
    f32(v.z);
  }
  void quat(const glm::quat& q) {
    f32(q.x);
    f32(q.y);
    f32(q.z);
    f32(q.w);
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

/// Simulation values that live outside the registry but belong to the state.
struct ChecksumExtras {
  std::uint64_t frame = 0;          ///< Steps completed.
  std::uint64_t seed = 0;           ///< The session seed.
  std::uint32_t previous_keys = 0;  ///< Held keys of the previous step (edge detection).
  bool split_view = false;          ///< G toggle state.
};

/// Hashes, for every entity with a Transform in storage order: its id, Transform (position,
/// rotation, scale, parent), RigidBody, Light enabled/moves, Camera and PlayerController;
/// then the extras. Deterministic for a deterministic sequence of registry operations.
std::uint64_t state_checksum(const engine::Registry& registry, const ChecksumExtras& extras);

}  // namespace game_demo
