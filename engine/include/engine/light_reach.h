#pragma once
// Where a static light can reach, given the static geometry: a voxel grid of light masks
// (bit i set: light i may light a surface in that voxel). The renderer shades each pixel
// with only the lights its voxel's mask names (docs/performance-frame.md): a light whose
// every ray to a point is blocked by static geometry contributes exactly zero there, and
// llvmpipe pays for every light a shader evaluates, lit or not.
//
// Conservative by construction where it can be, sampled where it cannot:
// - visibility is tested from the lattice points at the voxels' corners to each light
//   (a point light's position; 9 points over an area light's rectangle, on its emitting
//   side only) by segment-triangle tests against the occluders (both faces block);
// - a voxel's mask is the union of its 8 corners' masks, then dilated by one voxel in
//   every direction (26 neighbours), so a light seen from any corner within one voxel of
//   a voxel counts there;
// - the risk: light that passes through a gap narrower than the lattice spacing and lands
//   on a surface with no lit lattice point within one voxel is dropped. Occluders that may
//   move must not be passed (the renderer leaves out static items it has seen move).
// Outside the grid every bit is set (all lights).

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace engine {

struct ReachTriangle {
  glm::vec3 a{0.0f}, b{0.0f}, c{0.0f};
};

/// Occluding triangles with their bounds (a mesh instance): the segment test skips a group
/// whose box the segment misses.
struct ReachOccluder {
  std::vector<ReachTriangle> triangles;
  glm::vec3 min{0.0f}, max{0.0f};
};

struct ReachLight {
  glm::vec3 position{0.0f};
  /// Area lights (half_x, half_y non-zero): the rectangle position +- half_x +- half_y,
  /// emitting along `direction` only. Point and spot lights: zero half axes (a spot's cone
  /// is not used: the test stays conservative).
  glm::vec3 direction{0.0f, 0.0f, -1.0f};
  glm::vec3 half_x{0.0f};
  glm::vec3 half_y{0.0f};
};

struct LightReachGrid {
  static constexpr int kMaxLights = 8;
  glm::vec3 origin{0.0f};  ///< World position of voxel (0, 0, 0)'s minimum corner (m).
  float voxel_m = 0.5f;
  glm::ivec3 dims{0};               ///< Voxels per axis; 0: no grid (every point gets every light).
  std::vector<std::uint8_t> masks;  ///< x fastest, then y, then z.
  std::uint8_t all = 0;             ///< The mask with every light's bit (outside the grid).

  bool empty() const { return masks.empty(); }
  /// The mask of the voxel holding p; `all` outside the grid.
  std::uint8_t at(const glm::vec3& p) const;
};

/// At most LightReachGrid::kMaxLights lights (bit i = lights[i]). The grid covers
/// [min, max] padded by one voxel.
LightReachGrid build_light_reach_grid(const std::vector<ReachOccluder>& occluders,
                                      const std::vector<ReachLight>& lights, const glm::vec3& min, const glm::vec3& max,
                                      float voxel_m);

/// Whether the segment from p to q (ends excluded by `end_margin_m`) crosses a triangle.
bool segment_blocked(const std::vector<ReachOccluder>& occluders, const glm::vec3& p, const glm::vec3& q,
                     float end_margin_m);

}  // namespace engine
