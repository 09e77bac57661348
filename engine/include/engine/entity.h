#pragma once
// Entity handles: an index plus a generation, so a destroyed id never aliases a new entity.

#include <cstdint>
#include <functional>

namespace engine {

/// A handle to an entity of a Registry. Default-constructed handles are null.
///   engine::Entity e = registry.create();  if (registry.valid(e)) ...
struct Entity {
  static constexpr std::uint32_t kNullIndex = 0xffffffffu;
  std::uint32_t index = kNullIndex;
  std::uint32_t generation = 0;

  constexpr bool is_null() const { return index == kNullIndex; }
  constexpr explicit operator bool() const { return !is_null(); }
  friend constexpr bool operator==(Entity a, Entity b) = default;
  /// Packs index and generation into one 64-bit id (stable within a run; used in checksums).
  constexpr std::uint64_t id() const { return (std::uint64_t(generation) << 32) | index; }
};

inline constexpr Entity kNullEntity{};

}  // namespace engine

template <>
struct std::hash<engine::Entity> {
  std::size_t operator()(engine::Entity e) const noexcept { return std::hash<std::uint64_t>{}(e.id()); }
};
