#pragma once
// A diagnosis solver for antiradiance (issue 37, docs/antiradiance.md "Issue 37: what limits
// the change"): the same elements (an ElementHierarchy's leaves) and the same per-leaf direct
// light, but leaf-to-leaf transport by form factors with ray-traced visibility instead of
// antiradiance. Every pair of leaves gets the mean of cos_i cos_j V / r^2 over Monte Carlo
// point pairs on the two leaves' triangles (Embree occlusion through the posed scene); the
// indirect irradiance solves E_i = sum_j A_j G_ij albedo_j / pi (E_direct_j + E_j) (Jacobi, to a
// residual tolerance). It answers "how good could the change be at these elements with perfect
// visibility". Not a runtime method: its cost is n^2 point pairs.
//   auto t = gi::ExactLeafTransport::create(input, {}).value();
//   t.update(h);                            // every pair, at h's pose
//   t.set_instance_transform(door, m);  h.set_group_transform(1, m);
//   t.update(h);                            // only the pairs the door's motion can change
//   std::vector<glm::vec3> e = t.solve(h, direct).irradiance;
//
// Common random numbers: a pair's point samples depend only on (seed, pair, sample), so a pair
// whose visibility the motion cannot change keeps its value bit for bit, and the change between
// poses carries no noise from the pairs that did not change.

#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <gi/bake_input.h>

#include "antiradiance/element_hierarchy.h"
#include "antiradiance/moving_instances.h"
#include "raytrace/ray_caster.h"

namespace gi {

struct ExactTransportSettings {
  /// Monte Carlo point pairs per leaf pair (stratified on the first leaf); close pairs (centres
  /// nearer than twice their radii's sum) at least 16.
  int point_pairs = 64;
  /// Fewer point pairs for small leaves (0: off, point_pairs everywhere): a pair of leaves of
  /// areas A_i, A_j gets ceil(point_pairs A_i A_j / reference_area_m2^2) pairs, at least 1,
  /// at most point_pairs, and point_pairs when the leaves are close (centres nearer than twice
  /// their radii's sum). A leaf's irradiance sums ~1 / A_j senders per area, so its noise stays
  /// that of reference_area_m2 leaves at point_pairs (0.2 m leaves near a door: the n^2 pairs'
  /// rays 16-256x fewer). The count of a static pair does not depend on the pose.
  float reference_area_m2 = 0.0f;
  /// Converged when sum |dE| / sum |E| of a Jacobi step drops below this...
  double tolerance = 1e-3;
  /// ...and no leaf's step moves it by more than this share of its own E (of 1% of the mean E
  /// for the darkest leaves). The sum alone is the bright leaves': a corridor losing its light
  /// behind a shut door (1% of the room's level) stopped with most of its warm start left,
  /// keeping 0.17 of its light against the truth's 0.05 (0.11 at 1e-2, 0.06 at 1e-3; issue 37).
  double leaf_tolerance = 1e-3;
  int max_iterations = 1000;
  /// Indirect bounces: -1 all (to the tolerance), k >= 1: at most k (1: the first bounce off
  /// the directly lit leaves only).
  int bounces = -1;
  /// r^2 is clamped to at least this squared (metres): the 1/r^2 singularity of leaves that
  /// touch (a door's edge against its frame, a wall against the floor) is integrable but makes
  /// point pairs noisy.
  float min_distance_m = 0.02f;
  std::uint64_t seed = 1;
  /// Keep every point pair's visibility (one bit per sample; needs point_pairs <= 64) and, at
  /// a door move, trace only the samples of a recomputed static pair whose segment meets a
  /// moved instance's box before or after the move; the others reuse their stored bit (the
  /// geometry they cross did not move). The couplings are bit for bit those of tracing every
  /// sample; the rays per move drop to the segments that cross the door's two boxes. 2 bytes
  /// per leaf pair up to 16 point pairs (and close pairs' 16), 8 up to 64.
  bool reuse_visibility = false;
  /// Trace the rays of consecutive pairs together, a stream of up to 256 (rtcOccluded1M); false:
  /// one rtcOccluded1 per ray, as before. The couplings are the same bits either way. (Packets
  /// of 16, rtcOccluded16, hung inside Embree on the door scene's first update: not used.)
  bool streams = true;
  /// With reuse_visibility: the kept bits are each sample's visibility in the static part of
  /// the scene (traced there, on the first update and when a sample's ends move), and a
  /// sample is visible when its bit is set and, if a deforming instance's box now meets its
  /// segment, the deforming instances alone (their own small scene) do not occlude it. A door
  /// move then traces only the door's own pairs in the static scene and tests the static
  /// pairs' visible samples near the door against the door alone. The same bits (occluded in
  /// the scene = occluded by its static part or by an instance).
  bool door_only_rays = true;
};

struct ExactSolveResult {
  std::vector<glm::vec3> irradiance;  ///< Indirect irradiance per leaf (W/m^2), leaf order.
  int iterations = 0;
  double residual = 0.0;
  double leaf_residual = 0.0;  ///< The last step's largest share of one leaf's E (leaf_tolerance).
  bool converged = false;
};

class ExactLeafTransport {
 public:
  /// Errors: invalid input, ray caster construction failures, point_pairs < 1.
  static engine::Result<ExactLeafTransport> create(const BakeInput& input, const ExactTransportSettings& settings);

  /// Moves deforming instance `instance` (BakeInput index) in the ray caster; the next
  /// update() recomputes the pairs it can change. The caller moves the hierarchy's group.
  void set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world);
  /// The first call (or one with another leaf count): every pair. Later: the pairs with a
  /// leaf of a deforming instance, and those whose segment hull (the segment between the
  /// leaves' centres, widened by the larger bounding radius) meets a moved instance's bounds
  /// before or after its motion. Precondition: `h` is the hierarchy of the previous calls,
  /// its deforming groups placed as the instances were set here, corners present.
  void update(const ElementHierarchy& h);
  /// Pairs the last update() computed (unordered leaf pairs).
  std::size_t last_pairs_computed() const { return last_pairs_; }
  /// Rays the last update() cast.
  std::size_t last_rays() const { return last_rays_; }
  /// Rays the last update() cast against the deforming instances alone (door_only_rays; not
  /// in last_rays()).
  std::size_t last_door_only_rays() const { return last_door_only_rays_; }
  /// Of last_rays(): those of pairs with a leaf on a moved instance (their samples moved).
  std::size_t last_moving_rays() const { return last_moving_rays_; }
  /// The last update()'s time in the ray caster, summed over its threads (ms).
  double last_trace_cpu_ms() const { return last_trace_cpu_ms_; }

  /// The indirect irradiance with `direct` (W/m^2 per leaf) as the source.
  ExactSolveResult solve(const ElementHierarchy& h, std::span<const glm::vec3> direct) const;

  /// Restricts the transport to receivers (issue 37's explicit visibility near the door): set
  /// before the first update(), one flag per leaf. Only pairs with an end among them are
  /// computed (the others' coupling stays 0).
  void set_receivers(std::vector<char> receivers) {
    receivers_ = std::move(receivers);
    sized_ = false;
  }
  /// The receivers' flags per leaf (empty: every leaf).
  const std::vector<char>& receivers() const { return receivers_; }
  /// The receivers' indirect irradiance gathered with visibility from every leaf, the other
  /// leaves held at `others` (W/m^2 per leaf: e.g. an antiradiance solve's); the receivers'
  /// own exchange iterated to the tolerance. Returns every leaf's value (the others' as given).
  /// `start` (empty: 0): the receivers' first iterate, e.g. the previous pose's solution (a
  /// warm start: the same fixed point in fewer iterations).
  ExactSolveResult solve_receivers(const ElementHierarchy& h, std::span<const glm::vec3> direct,
                                   std::span<const glm::vec3> others, std::span<const glm::vec3> start = {}) const;

  /// G_ij of leaves i != j (m^-2: the mean of cos cos V / r^2); 0 for i == j (and, with
  /// receivers, for a pair of two leaves that are not).
  float coupling(std::size_t i, std::size_t j) const;
  /// Bytes of the couplings, the kept visibility and the receivers' rows. Without receivers
  /// n(n-1)/2 pairs; with them only the receivers' rows (receivers x n), where the couplings
  /// live and the visibility of each pair is kept once.
  /// table_bytes() per receiver and leaf at `point_pairs` (a coupling and the visibility's words).
  static std::size_t row_bytes_per_leaf(int point_pairs);
  std::size_t table_bytes() const {
    return g_.size() * sizeof(float) + visible_.size() * sizeof(std::uint16_t) + rows_.size() * sizeof(float);
  }

 private:
  struct PairBatch;  // pairs whose samples wait for their rays (the .cpp)
  /// Point pairs of leaves (ei, ej): point_pairs, at least kMinClosePairs when close, fewer
  /// with reference_area_m2.
  int point_pairs_of(const ElementNode& ei, const ElementNode& ej) const;
  /// Whether segment `r` meets a swept box (a kept sample is traced again).
  bool meets_swept(const Ray& r) const;
  /// door_only_rays: queues a sample's rays along `r` (`ray` in the static scene when `traced`,
  /// else `static_visible` is its stored bit; `door_ray` when a door's box now meets it).
  void queue_split_sample(const Ray& r, bool traced, bool static_visible, std::int32_t& ray, std::int32_t& door_ray,
                          PairBatch& batch) const;
  /// A deforming instance's world box at `m` (door_only_rays).
  MovingInstances::Box world_box(std::uint32_t instance, const glm::mat4& m) const;
  /// Queues the point samples of leaves (i, j), i < j, at the caster's current pose: their
  /// weights, and a ray for each sample to trace. With `reuse` (and stored visibility) only the
  /// samples whose segment meets a swept box get a ray, the others keep their stored bit.
  void queue_pair(const ElementHierarchy& h, std::size_t i, std::size_t j, bool reuse, PairBatch& batch) const;
  /// Traces the batch's rays (a stream, or one by one without `streams`), stores every
  /// queued pair's G and visibility bits, and empties the batch (counting its rays).
  void flush(PairBatch& batch);
  /// The pairs (i, j > i) of row i that update() recomputes, queued and flushed.
  void update_row(const ElementHierarchy& h, std::size_t i, bool all, std::span<const char> moving,
                  std::span<const MovingInstances::Box> bounds, PairBatch& batch);
  /// Whether a swept box can meet a segment between static leaves i and j (`bounds`: each
  /// leaf's triangle's box).
  bool pair_may_change(const ElementHierarchy& h, std::size_t i, std::size_t j,
                       std::span<const MovingInstances::Box> bounds) const;
  std::size_t pair_index(std::size_t i, std::size_t j) const;  // i < j
  /// Pair (i < j)'s place in visible_ (x visible_words_): pair_index without receivers, with
  /// them the place in rows_ of the first receiver's row (i's when it is one, else j's).
  std::size_t pair_slot(std::size_t i, std::size_t j) const;
  bool visible_bit(std::size_t slot, std::uint32_t s) const {
    return ((visible_[slot * visible_words_ + s / 16] >> (s % 16)) & 1u) != 0;
  }
  void set_visible_bit(std::size_t slot, std::uint32_t s, bool visible) {
    std::uint16_t& w = visible_[slot * visible_words_ + s / 16];
    const auto bit = static_cast<std::uint16_t>(1u << (s % 16));
    w = visible ? static_cast<std::uint16_t>(w | bit) : static_cast<std::uint16_t>(w & ~bit);
  }
  /// Sizes the tables for n leaves (every coupling 0) and the receivers' rows.
  void reset(std::size_t n);
  /// Jacobi over every leaf from zero (solve()'s; the receivers' solve is iterate_receivers).
  ExactSolveResult iterate(const ElementHierarchy& h, std::span<const glm::vec3> direct) const;
  /// The receivers' Jacobi on rows_: the senders held at `others` summed once per solve, the
  /// steps over the receivers' columns only.
  ExactSolveResult iterate_receivers(const ElementHierarchy& h, std::span<const glm::vec3> direct,
                                     std::span<const glm::vec3> others, std::span<const glm::vec3> start) const;
  /// Stores G of pair (i, j), i < j: in g_ without receivers, else in the receivers' rows.
  void store(std::size_t i, std::size_t j, float g);

  ExactTransportSettings settings_;
  std::unique_ptr<RayCaster> caster_;
  /// door_only_rays: caster_ holds the static instances only, door_caster_ the deforming ones;
  /// per BakeInput instance its index there (-1: static) and its object-space box; per
  /// deforming instance (door_caster_'s order) its world box now.
  std::unique_ptr<RayCaster> door_caster_;
  std::vector<std::int32_t> door_slot_;
  std::vector<MovingInstances::Box> door_box_, door_now_;
  MovingInstances moving_;
  bool dirty_ = false;
  bool sized_ = false;  ///< reset() ran for these receivers (update() computes every pair until then).
  std::size_t n_ = 0;
  /// Without receivers: every pair's G, upper triangle, row-major, i < j. With receivers:
  /// empty (rows_ holds their pairs; the demo level's 6666 leaves took 267 MB here).
  std::vector<float> g_;
  /// With reuse_visibility: per pair slot (pair_slot), visible_words_ words whose bit s is set
  /// when sample s is unoccluded (16 bits a word: 1 word up to 16 point pairs, 4 up to 64).
  std::vector<std::uint16_t> visible_;
  std::size_t visible_words_ = 1;
  std::vector<char> receivers_;
  /// With receivers: their leaf indices in order, and every receiver's row of couplings to all
  /// n leaves (receivers x n, row-major; a pair of two receivers in both rows): the only copy
  /// of the couplings, which the receivers' solve walks densely.
  std::vector<std::uint32_t> recv_;
  std::vector<std::int32_t> slot_;  ///< Per leaf: its row in rows_, or -1.
  std::vector<float> rows_;
  std::size_t last_pairs_ = 0, last_rays_ = 0, last_moving_rays_ = 0, last_door_only_rays_ = 0;
  double last_trace_cpu_ms_ = 0.0;
};

}  // namespace gi
