#pragma once
// Where reflection probes go: one per room-sized volume of the static world's free space,
// each with the axis-aligned box its parallax correction projects onto
// (docs/reflection_probes.md, "Placement").
//   auto probes = gi::place_probes(caster, world_min, world_max, {.cell_m = 4.0f});
//
// The rule: candidate points at the centres of a grid of cells of about cell_m over the
// static world's bounds, visited in grid order (y, then z, then x), then those of a grid of
// cell_m / 2 (a room narrower than a cell, a corridor, can lie between the first grid's
// candidates). A candidate already
// inside a placed probe's box is skipped. From the others, 6 bundles of 5 x 5 parallel
// rays (spread +-spread_m across the ray) go along +-x, +-y, +-z; each side of the box is at
// the median distance of its bundle, so an opening (a doorway) or an obstacle (a crate, a
// column) that covers less than half the bundle neither opens the box into the next room nor
// closes it in front of the wall. A candidate whose centre rays hit
// a back face is inside solid geometry and places nothing; rays that escape stop at the
// world's bounds (outdoors). The probe sits at its box's centre when that point is free,
// else at the candidate. Boxes thinner than min_box_m are dropped.

#include <vector>

#include <glm/glm.hpp>

#include "raytrace/ray_caster.h"

namespace gi {

struct ProbePlacementSettings {
  float cell_m = 4.0f;     ///< Candidate spacing: about a room's size (> 0).
  float spread_m = 1.0f;   ///< Half-width of a ray bundle: openings and obstacles under half of it do not count.
  float min_box_m = 0.5f;  ///< Smallest box side kept.
  int max_probes = 64;     ///< Placement stops at this many.
};

/// One probe: where its cube map is captured and the box that stands for its room.
struct ProbeVolume {
  glm::vec3 centre{0.0f};
  glm::vec3 box_min{0.0f};
  glm::vec3 box_max{0.0f};
  bool contains(const glm::vec3& p) const {
    return glm::all(glm::greaterThanEqual(p, box_min)) && glm::all(glm::lessThanEqual(p, box_max));
  }
};

/// The probes of the static world `caster` traces, whose geometry lies in [world_min, world_max].
std::vector<ProbeVolume> place_probes(const RayCaster& caster, const glm::vec3& world_min, const glm::vec3& world_max,
                                      const ProbePlacementSettings& settings);

}  // namespace gi
