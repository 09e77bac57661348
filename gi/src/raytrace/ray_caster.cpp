#include "raytrace/ray_caster.h"

#include <engine/check.h>

namespace gi {

void RayCaster::intersect_many(std::span<const Ray> rays, std::span<Hit> hits) const {
  GI_EXPECTS(rays.size() == hits.size(), "one hit per ray");
  for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = intersect(rays[i]);
}

void RayCaster::occluded_many(std::span<const Ray> rays, std::span<std::uint8_t> out) const {
  GI_EXPECTS(rays.size() == out.size(), "one result per ray");
  for (std::size_t i = 0; i < rays.size(); ++i) out[i] = occluded(rays[i]) ? 1 : 0;
}

void RayCaster::occluded_coherent(std::span<const Ray> rays, std::span<std::uint8_t> out) const {
  occluded_many(rays, out);
}

}  // namespace gi
