#pragma once
// Whether a segment meets an axis-aligned box (the slab test): the broad phase of every CPU
// visibility query that walks boxes before triangles.
//   if (engine::segment_meets_box(origin, to - origin, 1.0f, box_lo, box_hi)) { ...test its triangles... }

#include <algorithm>
#include <utility>
#include <glm/glm.hpp>

namespace engine {

/// Whether p + t d for some t in [0, t_max] lies in the box [lo, hi] (faces included).
/// d need not be normalized; t_max may be infinite (a ray). A zero component of d tests p
/// against that slab alone.
inline bool segment_meets_box(const glm::vec3& p, const glm::vec3& d, float t_max, const glm::vec3& lo,
                              const glm::vec3& hi) {
  float t0 = 0.0f, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    const float inv = 1.0f / d[a];
    float ta = (lo[a] - p[a]) * inv, tb = (hi[a] - p[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace engine
