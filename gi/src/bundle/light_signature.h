#pragma once
// A fingerprint of everything about a light entity that changes the light it sends: on/off,
// type, colour, intensity, range, cone, area size and world placement. Runtimes compare it
// between frames to recompute only for lights that changed.
//   if (light_signature(e, light, wt) != cached.signature) recompute(e);

#include <cstdint>

#include <engine/components.h>
#include <engine/entity.h>

#include "io/content_hash.h"

namespace gi {

inline std::uint64_t light_signature(engine::Entity e, const engine::Light& l, const engine::WorldTransform& wt) {
  ContentHash h;
  h.add_value(e.id());
  h.add_value(static_cast<std::uint8_t>(l.enabled));
  h.add_value(static_cast<std::uint8_t>(l.type));
  h.add_value(l.color.x), h.add_value(l.color.y), h.add_value(l.color.z);
  h.add_value(l.intensity), h.add_value(l.range_m);
  h.add_value(l.inner_cone_rad), h.add_value(l.outer_cone_rad);
  h.add_value(l.area_size_m.x), h.add_value(l.area_size_m.y);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) h.add_value(wt.matrix[c][r]);
  return h.value();
}

}  // namespace gi
