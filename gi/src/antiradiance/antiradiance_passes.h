#pragma once
// The four operations of one antiradiance iteration (Dachsbacher et al. 2007, §3.1-3.2,
// §4.2) as an interface with two implementations: the CPU twin (CpuAntiradiancePasses,
// here) and the compute shaders (AntiradianceGpuPass, antiradiance_gpu_pass.h). Both keep
// the same tables and sum in the same order, so the tests compare them value by value;
// run_antiradiance() (antiradiance_solver.h) drives either through the same schedule.
//
// Tables (bins = m, nodes and leaves of the hierarchy, RGB per entry):
//   I_ex[node][bin]   exitant intensity I_L - I_A (W/sr): leaves from the local pass, inner
//                     nodes the sum of their leaves (pull)
//   L_in[node][bin]   incident radiance gathered over the node's links (global pass), then
//                     plus its ancestors' (push, level by level from the root: at a leaf it
//                     is all the light arriving there)
//   I_L, I_A[leaf][bin]  reflected intensity (eq. 18, diffuse) and antiradiance (eq. 19)
//   E[leaf]           indirect irradiance (W/m^2) gathered by the last radiance step
//
//   gi::CpuAntiradiancePasses cpu(hierarchy, bins, links);
//   cpu.reset(direct);  cpu.global();  cpu.push();  cpu.local(true, true);  cpu.pull();

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "antiradiance/directional_bins.h"
#include "antiradiance/element_hierarchy.h"
#include "antiradiance/link_mesh.h"

namespace gi {

/// The nodes of `h` ordered by depth (root first) and each depth's range in that order
/// (offsets has depth count + 1 entries): what push and pull walk level by level.
void nodes_by_level(const ElementHierarchy& h, std::vector<std::int32_t>& nodes, std::vector<std::uint32_t>& offsets);

/// Sums of a local pass over all leaves (each leaf's partial sum in float, bins then
/// channels; leaves summed in double in leaf order).
struct LocalPassSums {
  double change = 0.0;     ///< sum |I_ex new - I_ex old|
  double magnitude = 0.0;  ///< sum |I_ex new|
};

class AntiradiancePasses {
 public:
  virtual ~AntiradiancePasses() = default;
  /// Starts from the direct light: I_L = a <n|w>+ albedo/pi E_direct (eq. 18 with the direct
  /// irradiance, no antiradiance: "shadowing of the direct illumination is done by the
  /// shadow map", §3.3), I_A = 0, E = 0; pulls. `direct`: W/m^2 per leaf.
  virtual void reset(std::span<const glm::vec3> direct) = 0;
  /// Starts from the tables of the last solve instead (a warm start: the solution of the
  /// previous pose is the first iterate, so a door moved a little needs few iterations to the
  /// same fixed point): takes the new direct light (W/m^2 per leaf) and the leaves' current
  /// normals and areas, keeps I_ex, I_L, I_A and E. Precondition: reset() ran before.
  virtual void warm_start(std::span<const glm::vec3> direct) = 0;
  /// Global pass (operator U, eq. 16): L_in[r][bin] = sum over r's links of F I_ex[s][bin].
  virtual void global() = 0;
  /// Push: level by level from the root's children down, L_in[n] += L_in[parent(n)].
  virtual void push() = 0;
  /// Local pass at the leaves (L = L_in of the leaf's node after push): K (eq. 18, diffuse:
  /// E = sum_b <n|-w_b>+ L[b] omega_b, I_L[b] = a <n|w_b>+ albedo/pi (E + E_direct)) when
  /// `radiance`, J (eq. 19: I_A[b] = a <n|-w_b>+ L[b]) when `antiradiance`; I_ex = I_L - I_A.
  virtual LocalPassSums local(bool radiance, bool antiradiance) = 0;
  /// Pull: level by level from the deepest up, I_ex of an inner node = the sum of its
  /// children's I_ex (in child order).
  virtual void pull() = 0;
  /// Indirect irradiance per leaf (W/m^2) from the last radiance step.
  virtual std::vector<glm::vec3> irradiance() const = 0;
};

/// The CPU twin: loops over the tables, float sums in the shaders' order. Each pass runs its
/// items (receivers, nodes of a level, leaves) on TBB's threads, every item writing only its
/// own entries: bit for bit the same tables for any thread count.
class CpuAntiradiancePasses final : public AntiradiancePasses {
 public:
  /// Keeps references: the hierarchy, bins and links must outlive it (their sizes must not change).
  CpuAntiradiancePasses(const ElementHierarchy& h, const DirectionalBins& bins, const LinkMesh& links);
  void reset(std::span<const glm::vec3> direct) override;
  void warm_start(std::span<const glm::vec3> direct) override;
  void global() override;
  void push() override;
  LocalPassSums local(bool radiance, bool antiradiance) override;
  void pull() override;
  std::vector<glm::vec3> irradiance() const override { return e_; }

  /// The tables, for tests (RGB triples, row-major [row][bin]).
  const std::vector<glm::vec3>& exitant() const { return i_ex_; }

 private:
  const ElementHierarchy& h_;
  const DirectionalBins& bins_;
  const LinkMesh& links_;
  int m_ = 0;
  std::vector<glm::vec3> i_ex_, l_in_, i_l_, i_a_, e_, direct_;
  std::vector<std::int32_t> by_level_;        ///< Nodes ordered by depth (root first).
  std::vector<std::uint32_t> level_offsets_;  ///< by_level_ range of each depth.
  std::vector<glm::vec2> leaf_sums_;          ///< The local pass's (change, magnitude) per leaf.
};

}  // namespace gi
