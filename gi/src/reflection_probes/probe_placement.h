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
// else at the candidate (or capture_height above its box's floor). Boxes thinner than min_box_m are dropped.
// Optionally, a box much longer than wide (corridor_aspect) becomes segments about as long as it is wide, each with its
// own probe at its centre and its own box, reaching kProbeFadeM / 2 into its neighbours' so the forward pass fades
// between them.
// Last, a box whose probe does not see enough of its floor (second_view_min_share) gets a second probe with
// the same box over the hidden part (hidden_receivers, second_view_point), appended after all the others.

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "raytrace/ray_caster.h"

namespace gi {

struct ProbePlacementSettings {
  float cell_m = 4.0f;     ///< Candidate spacing: about a room's size (> 0).
  float spread_m = 1.0f;   ///< Half-width of a ray bundle: openings and obstacles under half of it do not count.
  float min_box_m = 0.5f;  ///< Smallest box side kept.
  int max_probes = 64;     ///< Placement stops at this many.
  /// When > 0, a box whose longer horizontal side is more than this times its shorter one (a
  /// corridor) is cut across its length into segments about as long as it is wide, a probe
  /// each, so no point of it lies far from a probe's centre. Off (0) by default: on the demo
  /// corridor (2) the segments' level 0 is closer to the truth, but the lookup reads them
  /// worse (docs/reflection_probes.md, "Where the corridor's error comes from"). Not stored in
  /// the bundle (the boxes are).
  float corridor_aspect = 0.0f;
  /// When > 0, each probe is captured this far (m) above its box's floor (at most halfway up),
  /// where the floor's reflections are seen, instead of at the box's middle; the parallax
  /// correction reads from that point (docs/reflection_probes.md, "Capture height"). 0 (the
  /// default): the box's middle. Not stored in the bundle (the capture points are).
  float capture_height = 0.0f;
  /// A second viewpoint where the first is blocked (docs/reflection_probes.md, "A second viewpoint
  /// where the first is blocked"): when more than this share of a box's receivers (hidden_receivers)
  /// is hidden from its probe, a second probe with the same box is captured over the hidden ones
  /// (second_view_point); the forward pass weighs each by whether it saw the shaded point
  /// (probe_visibility_weight). > 1: never; < 0: every box, over its middle (a measurement, not a
  /// placement rule). Not stored in the bundle (the capture points are).
  float second_view_min_share = 0.05f;
  float second_view_height = 0.8f;  ///< The second viewpoint's height (m) above its box's floor (at most halfway up).
  float receiver_step_m = 0.25f;    ///< Spacing (m) of the receiver samples over the box's floor.
};

/// How far (m) the segments of a cut box reach into their neighbours: the width over which
/// the forward pass fades from one segment's probe to the next (the shader's PROBE_FADE_M).
inline constexpr float kProbeFadeM = 0.5f;

/// One probe: where its cube map is captured and the box that stands for its room.
struct ProbeVolume {
  glm::vec3 centre{0.0f};
  glm::vec3 box_min{0.0f};
  glm::vec3 box_max{0.0f};
  bool contains(const glm::vec3& p) const {
    return glm::all(glm::greaterThanEqual(p, box_min)) && glm::all(glm::lessThanEqual(p, box_max));
  }
};

/// The upward-facing surfaces (floors, the tops of blocks) of v's box, sampled on a grid of `step` m over
/// its floor (the first surface below each grid point, 1 cm above it), and which of them v's centre
/// does not see (a ray from the centre towards the sample stops 2 cm or more short of it).
struct HiddenReceivers {
  int samples = 0;
  int hidden = 0;
  glm::vec3 centroid{0.0f};  ///< Of the hidden samples.
  [[nodiscard]] float share() const {
    return samples > 0 ? static_cast<float>(hidden) / static_cast<float>(samples) : 0.0f;
  }
};
HiddenReceivers hidden_receivers(const RayCaster& caster, const ProbeVolume& v, float step);

/// The second viewpoint of v's box: the hidden receivers' centroid at `height` above the box's floor (at
/// most halfway up), pushed off geometry: the nearest point of a 0.25 m grid around it (up to 1 m away, in
/// the box) with no surface within 0.3 m along the axes; nullopt when there is none.
std::optional<glm::vec3> second_view_point(const RayCaster& caster, const ProbeVolume& v, const HiddenReceivers& h,
                                           float height);

/// The probes of the static world `caster` traces, whose geometry lies in [world_min, world_max].
std::vector<ProbeVolume> place_probes(const RayCaster& caster, const glm::vec3& world_min, const glm::vec3& world_max,
                                      const ProbePlacementSettings& settings);

/// The weight of probe `v` at point p in the forward pass's blend (the shader's probe_weight):
/// 0 outside its box grown by `margin`, else the product over the axes of clamp(depth /
/// kProbeFadeM, 1e-3, 1), depth p's distance from the box's nearer side along the axis
/// (negative within the margin). The blend divides by the weights' sum, so the factors of the sides every box holding
/// p shares (a room's floor and walls) cancel, and across the overlap of two segments the
/// weights fade linearly from one probe to the next.
float probe_blend_weight(const ProbeVolume& v, const glm::vec3& p, float margin);

}  // namespace gi
