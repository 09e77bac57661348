#pragma once
// Explicit visibility near a deforming instance (issue 37, docs/antiradiance.md "Issue 37:
// the change scored against a split truth"): the leaves of an antiradiance region within a
// radius of the instance's reach (and the instance's own leaves) gather their light from every
// leaf through ExactLeafTransport (form factors with ray-traced visibility), the other leaves
// held at the region's antiradiance solve. The couplings of the baked pose are computed once
// (bake-time work); a move recomputes the pairs the motion can change and, with the
// visibility kept, traces only the samples whose segment meets the instance's boxes.
//   region.update(false);  auto near = gi::NearDoorVisibility::create(input, region, door, {}).value();
//   region.set_instance_transform(door, m); region.update();
//   std::vector<glm::vec3> e = near.move(region, door, m);   // indirect W/m^2 per leaf
//   e[l] - near.baseline()[l]                                  // the change at leaf l

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <gi/bake_input.h>

#include "antiradiance/antiradiance_exact_transport.h"
#include "antiradiance/antiradiance_region.h"

namespace gi {

struct NearDoorVisibilitySettings {
  /// Leaves whose bounding sphere comes within this many metres of the sphere the instance
  /// reaches about its origin (its farthest vertex) are receivers.
  float radius_m = 1.0f;
  /// Beyond radius_m, more leaves become receivers, nearest that sphere first, while the
  /// receivers' rows (table_bytes(): receivers x leaves x
  /// ExactLeafTransport::row_bytes_per_leaf) fit this many
  /// bytes; 0: the radius alone. The light beyond a shut door reaches its far side over several
  /// bounces, which antiradiance outside the set does not darken (docs/antiradiance.md
  /// "A near set as large as its budget").
  std::size_t budget_bytes = 0;
  /// Point pairs per leaf pair (close pairs at least 16; at most 64 with the visibility kept).
  int point_pairs = 16;
  bool reuse_visibility = true;
  /// A move's solve starts from the previous pose's receivers (else from 0).
  bool warm_start = true;
  /// The receivers' solve stops when a Jacobi step changes them by less than this (sum |dE| /
  /// sum |E|). Tighter than the region's 1e-3: the change is a fraction of the light, and at
  /// 1e-3 a warm-started solve stopped early enough to cost 0.007 of the level on the
  /// corridor (docs/antiradiance.md); each step is cheap next to the couplings' update.
  double tolerance = 1e-4;
  std::uint64_t seed = 1;
  /// Rays in streams (ExactTransportSettings::streams; the same couplings).
  bool streams = true;
  /// Kept visible samples tested against the door alone (ExactTransportSettings::door_only_rays;
  /// the same couplings).
  bool door_only_rays = true;
};

/// The settings an antiradiance bake's preset asks the runtime for (its near_visibility_*).
NearDoorVisibilitySettings near_door_settings(const AntiradianceSettings& s);

/// The leaves NearDoorVisibility::create makes receivers around deforming instance `door` (at
/// its transform in `input`): the instance's own leaves, those whose bounding sphere comes within
/// radius_m of the sphere the instance reaches about its origin (its farthest vertex), then,
/// within budget_bytes, the others nearest that sphere first. One rule for the class, the
/// runtime and the planner. No receiver where `door` names no instance of `input` (or its
/// instance no mesh).
std::vector<char> near_door_receivers(const BakeInput& input, const ElementHierarchy& h, std::uint32_t door,
                                      const NearDoorVisibilitySettings& settings);

class NearDoorVisibility {
 public:
  /// Marks the receivers around deforming instance `door` (at its transform in `input`, the
  /// baked pose) and computes that pose's couplings and the receivers' solve, the others at
  /// the region's baked solution. Precondition: the region's direct light is at the baked
  /// pose (region.update(false) after loading). Errors: a `door` that is not deforming, the
  /// transport's (bad input, more than 64 point pairs with the visibility kept).
  static engine::Result<NearDoorVisibility> create(const BakeInput& input, const AntiradianceRegion& region,
                                                   std::uint32_t door, const NearDoorVisibilitySettings& settings);

  /// After the region moved `door` to `object_to_world` and solved: the receivers' indirect
  /// irradiance with visibility, the others' the region's (W/m^2 per leaf).
  std::vector<glm::vec3> move(const AntiradianceRegion& region, std::uint32_t door, const glm::mat4& object_to_world);

  /// Every leaf's indirect irradiance at the baked pose (the change's zero).
  const std::vector<glm::vec3>& baseline() const { return baseline_; }
  /// Leaves that gather with visibility (near_door_receivers), and their mask per leaf.
  std::size_t receivers() const { return receivers_; }
  const std::vector<char>& receiver_mask() const { return transport_.receivers(); }
  /// CPU bytes of its couplings and kept visibility (the receivers' rows).
  std::size_t table_bytes() const { return transport_.table_bytes(); }
  /// The last move's (or create's) recomputed leaf pairs and traced rays.
  std::size_t last_pairs() const { return transport_.last_pairs_computed(); }
  std::size_t last_rays() const { return transport_.last_rays(); }
  /// Rays against the door alone (not in last_rays()).
  std::size_t last_door_only_rays() const { return transport_.last_door_only_rays(); }
  /// Of last_rays(): the door's own pairs' (their samples moved with it).
  std::size_t last_moving_rays() const { return transport_.last_moving_rays(); }
  /// The last update's time in the ray caster, summed over its threads (ms).
  double last_trace_cpu_ms() const { return transport_.last_trace_cpu_ms(); }
  /// The last move's time in the couplings' update and in the receivers' solve, ms.
  double last_update_ms() const { return update_ms_; }
  double last_solve_ms() const { return solve_ms_; }
  /// The last move's receivers' solve: Jacobi iterations (to the region's tolerance).
  int last_iterations() const { return iterations_; }

 private:
  explicit NearDoorVisibility(ExactLeafTransport transport) : transport_(std::move(transport)) {}

  ExactLeafTransport transport_;
  std::vector<glm::vec3> baseline_, last_;
  bool warm_start_ = true;
  std::size_t receivers_ = 0;
  int iterations_ = 0;
  double update_ms_ = 0.0, solve_ms_ = 0.0;
};

}  // namespace gi
