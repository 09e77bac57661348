#pragma once
// One deforming region solved by antiradiance (Dachsbacher et al. 2007) on the CPU: the
// elements, bins and links (element_hierarchy.h, directional_bins.h, link_mesh.h), the
// direct light at the elements (antiradiance_direct_light.h) and the iteration
// (antiradiance_solver.h). A frame where a deforming instance moved: set its transform,
// then update(): relinks only the moved groups, recomputes the direct light and solves.
// The GPU twin (antiradiance_gpu_pass.h) runs the same passes over the region's tables.
//
// What it outputs (a deviation from the paper, docs/antiradiance.md): the light atlas (and
// the PRM) bake the world with its deforming instances at their authored pose, with
// visibility; the region adds the change their motion makes. The bake solves the baseline
// once, at the authored pose; delta() = E(now) - E(baseline) per leaf, 0 while nothing has
// moved. Nothing is counted twice (the atlas holds the authored pose, the delta only the
// change) and nothing goes stale (the delta covers the moved instances' own leaves and
// every static leaf they exchange light with). Antiradiance's discretization leaks (light
// through walls, the paper's §5 and Fig. 13) are the same in both solves wherever the
// geometry did not move and cancel in the delta, instead of adding light the baked atlas
// already shadows correctly.
//   auto region = gi::AntiradianceRegion::create(input, settings).value();
//   region.set_instance_transform(door, m);  region.update();
//   std::vector<glm::vec3> e = region.irradiance();   // indirect W/m^2 per leaf

#include <memory>
#include <utility>
#include <vector>

#include <engine/result.h>
#include <gi/bake_input.h>

#include "antiradiance/antiradiance_direct_light.h"
#include "antiradiance/antiradiance_passes.h"
#include "antiradiance/antiradiance_settings.h"
#include "antiradiance/antiradiance_solver.h"
#include "antiradiance/antiradiance_texel_blend.h"
#include "antiradiance/directional_bins.h"
#include "antiradiance/element_hierarchy.h"
#include "antiradiance/link_mesh.h"

namespace gi {

/// What a bake precomputes for a region (and a bundle stores, antiradiance_io.h): the
/// elements, the links between static elements and the baseline solve. The links with an
/// end in a deforming group are rebuilt when the region is made (they depend on the pose).
struct AntiradianceBake {
  AntiradianceSettings settings;
  ElementHierarchy hierarchy;
  LinkMesh static_links;
  std::vector<glm::vec3> baseline;  ///< Indirect irradiance per leaf with the region at its baked pose.
  /// How the baseline's solve ended (iterations, residual, budget_exhausted); not stored in a bundle.
  AntiradianceSolveReport baseline_report;
  /// What the bake's stages took (wall seconds; bake_stats.json, not the bundle's files):
  /// the links (or, in a merge of shards, putting the shards' links in place), the static
  /// links' filter, the direct light and the baseline solve.
  struct StageSeconds {
    double links = 0.0, static_links = 0.0, direct = 0.0, solve = 0.0;
  } seconds;
  /// What a load with the deforming groups at their baked pose would compute, computed by
  /// the bake (prepare_antiradiance_load) and stored (antiradiance_io.h) so the load only
  /// reads it: the links with an end in a deforming group (posed_links) and the runtime
  /// atlas's texel blends. Absent (present false): the load computes both.
  struct AtBakedPose {
    bool present = false;
    LinkMesh links;                        ///< posed_links of every deforming group.
    std::uint64_t layout_fingerprint = 0;  ///< atlas_layout_fingerprint of the layout `blends` cover (0: none).
    std::vector<AntiradianceTexelBlend> blends;
  } at_baked_pose;
};

/// Fills bake.at_baked_pose: the posed links of every deforming group at the baked pose and,
/// when `layout` is given (the atlas the runtime composites into: the bundle's light atlas,
/// else its PRM), its texel blends. Bit for bit what AntiradianceRegion::create and
/// AntiradianceLighting would compute from the bake at that pose.
void prepare_antiradiance_load(AntiradianceBake& bake, const BakeInput& input, const AtlasLayout* layout);

/// Builds the elements, links the static ones and solves the baseline. Errors: see
/// build_element_hierarchy and AntiradianceDirectLight::create; bins_per_side outside [1, 64].
engine::Result<AntiradianceBake> bake_antiradiance(const BakeInput& input, const AntiradianceSettings& settings);

/// Distributed bakes (docs/distributed-bake.md): shard `shard`'s part of the linking, most of
/// the bake (link_elements_shard over the hierarchy bake_antiradiance builds).
engine::Result<LinkMesh> bake_antiradiance_links_shard(const BakeInput& input, const AntiradianceSettings& settings,
                                                       const WorkShard& shard);
/// The bake from every shard's links (parts[i] of shard i of parts.size()): the same bake,
/// bit for bit, as bake_antiradiance. Errors: bake_antiradiance's and merge_link_shards'.
engine::Result<AntiradianceBake> bake_antiradiance_from_link_shards(const BakeInput& input,
                                                                    const AntiradianceSettings& settings,
                                                                    const std::vector<std::vector<Link>>& parts);

/// Counters of the last update().
struct AntiradianceUpdateCounters {
  std::size_t moved_groups = 0;
  std::size_t relinked_elements = 0;  ///< Elements whose links were rebuilt.
  std::size_t links_made = 0;         ///< Links built by the relink.
  std::size_t links = 0;              ///< Links in all after it.
  std::size_t direct_leaves = 0;      ///< Leaves whose direct light was recomputed (the others cannot change).
};

class AntiradianceRegion {
 public:
  /// Errors: see build_element_hierarchy and AntiradianceDirectLight::create; bins_per_side
  /// outside [1, 64].
  static engine::Result<AntiradianceRegion> create(const BakeInput& input, const AntiradianceSettings& settings);
  /// From a bake (made for `input`'s geometry): links the deforming groups at the poses
  /// `input` gives them, computes the direct light. Errors: the bake's deforming instances
  /// are not `input`'s, ray caster failures.
  static engine::Result<AntiradianceRegion> create(const BakeInput& input, AntiradianceBake bake);

  /// Moves deforming instance `instance` (BakeInput index). Returns false (and does nothing)
  /// when it is not a deforming instance of the region or the matrix equals the current one.
  bool set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world);
  /// Relinks what moved since the last update (nothing when nothing moved) and recomputes
  /// the direct light; then solves on the CPU unless `solve` is false (the GPU twin solves).
  /// The first solve starts cold (from the direct light: at the baked pose bit for bit the
  /// baseline's computation); later ones start from the last solve's tables when
  /// settings().warm_start is set and that solve converged (to the tolerance, within the
  /// budget, without diverging). With every deforming
  /// group back at its baked transform (posed_as_baked) after a first solve, the solve is
  /// skipped and irradiance() is the baseline: the change is exactly 0 there.
  AntiradianceSolveReport update(bool solve = true);

  /// Indirect irradiance (W/m^2) per leaf of the last CPU solve (its energy guard applied);
  /// the baseline when that update found the region posed as baked.
  std::vector<glm::vec3> irradiance() const {
    if (!adopted_.empty()) return adopted_;
    if (showing_baseline_) return baseline_;
    std::vector<glm::vec3> e = cpu_->irradiance();
    for (glm::vec3& v : e) v *= last_.output_scale;
    return e;
  }
  /// A solve made elsewhere (the GPU twin's, read back, its energy guard applied): irradiance()
  /// returns it until the next update(). What near-door visibility holds the other leaves at.
  void adopt_irradiance(std::vector<glm::vec3> irradiance) { adopted_ = std::move(irradiance); }
  /// The exitant intensities I_ex of the last CPU solve (nodes x bins RGB, W/sr; its energy
  /// guard applied): what gather_at_points reads (antiradiance_texel_gather.h). An update
  /// that skipped the solve (posed as baked) leaves them as they were.
  std::vector<glm::vec3> exitant() const {
    std::vector<glm::vec3> i = cpu_->exitant();
    for (glm::vec3& v : i) v *= last_.output_scale;
    return i;
  }
  /// The next solve starts from the direct light, as the first (what a GPU twin made afresh
  /// does, for comparisons).
  void discard_solution() { warm_startable_ = false; }
  /// The report of the last CPU solve.
  const AntiradianceSolveReport& last_report() const { return last_; }
  /// The baseline's indirect irradiance per leaf (the region at its baked pose).
  const std::vector<glm::vec3>& baseline() const { return baseline_; }
  /// What the region adds: `irradiance` (a solve's result per leaf) minus the baseline.
  std::vector<glm::vec3> delta(const std::vector<glm::vec3>& irradiance) const;
  const std::vector<glm::vec3>& direct() const { return direct_; }
  const ElementHierarchy& hierarchy() const { return *hierarchy_; }
  const DirectionalBins& bins() const { return *bins_; }
  const LinkMesh& links() const { return *links_; }
  const AntiradianceSettings& settings() const { return settings_; }
  const AntiradianceUpdateCounters& counters() const { return counters_; }
  /// True while every deforming group is at the pose it was baked at (since create, before
  /// any move): the bake's AtBakedPose then holds what the region would compute.
  bool at_baked_pose() const { return at_baked_pose_; }
  /// True while every deforming group's transform equals the one it was baked at (also after
  /// moving away and back): the change there is 0 by definition.
  bool posed_as_baked() const;

 private:
  AntiradianceSettings settings_;
  // Held by pointer so the CPU passes' references stay valid when the region moves.
  std::unique_ptr<DirectionalBins> bins_;
  std::unique_ptr<ElementHierarchy> hierarchy_;
  std::unique_ptr<LinkMesh> links_;
  std::unique_ptr<AntiradianceDirectLight> direct_light_;
  std::unique_ptr<CpuAntiradiancePasses> cpu_;
  std::vector<glm::vec3> direct_;
  std::vector<glm::vec3> baseline_;
  std::vector<glm::vec3> adopted_;          ///< adopt_irradiance's, until the next update().
  std::vector<glm::mat4> baked_transform_;  ///< Per deforming group g: [g - 1], as baked.
  std::vector<int> moved_;
  AntiradianceSolveReport last_;
  AntiradianceUpdateCounters counters_;
  bool at_baked_pose_ = false;
  bool solved_ = false;            ///< The CPU passes hold a solve.
  bool warm_startable_ = false;    ///< ... one that converged (a warm start can use it).
  bool showing_baseline_ = false;  ///< The last update found the region posed as baked.
};

}  // namespace gi
