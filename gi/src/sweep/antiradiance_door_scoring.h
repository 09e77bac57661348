#pragma once
// The door of the antiradiance sweep (antiradiance_sweep.h): the scene at its baked pose and
// the compared texels, the door's references (one path-traced stream, or two stacked for the
// split truth) and the scores of a run's change against them. Shared by the method's runs
// (antiradiance_sweep.cpp) and the diagnosis runs (antiradiance_diagnosis_sweep.cpp).
//   auto d = gi::antiradiance_sweep::door_setup(scene, 8.0, 1.0, "-50+-25+50").value();
//   DoorMoveScores sc;  sc.start(reference, d);  sc.add_pose(reference, d, 1, change_per_texel);

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/rgb_field.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "antiradiance/antiradiance_solver.h"
#include "antiradiance/antiradiance_texel_blend.h"
#include "sweep/sweep_method.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi::antiradiance_sweep {

// Swings about the door's local Y from its authored (baked) pose, degrees. The corridor's
// door is authored at 50 degrees open: the sweep's poses are 0 (shut), 25 and 100; the knob
// `swings` scores other ones (issue 37's angle in no sweep: +25, the door at 75 degrees).
inline constexpr float kSweepSwings[] = {-50.0f, -25.0f, 50.0f};
inline constexpr const char* kSweepSwingsKey = "-50+-25+50";
inline const std::vector<std::string> kSwingChoices = {kSweepSwingsKey, "+25", "+10"};

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The scene at the baked pose, its atlas and the compared texels.
struct DoorSetup {
  BakeInput input;
  std::uint32_t door = 0;
  glm::mat4 authored{1.0f};
  AtlasLayout layout;
  AtlasTexels texels;
  std::vector<std::uint8_t> mask;  // per texel: compared
  std::size_t compared = 0;
  std::vector<float> swings;  // the moved poses, degrees from the baked one

  // The baked pose and every moved one.
  std::size_t poses() const { return 1 + swings.size(); }

  glm::mat4 pose(float swing_deg) const {
    return authored * glm::rotate(glm::mat4(1.0f), glm::radians(swing_deg), glm::vec3(0.0f, 1.0f, 0.0f));
  }
  BakeInput posed(float swing_deg) const {
    BakeInput in = input;
    in.instances[door].object_to_world = pose(swing_deg);
    return in;
  }
};

/// The corridor-like scene's door (its first deforming instance), its atlas at `density`
/// texels/m and the static texels within `radius` metres of the door's swept bounds.
engine::Result<DoorSetup> door_setup(const SweepScene& scene, double density, double radius, const std::string& swings);

/// The "atlas_indirect_irradiance_door" reference provider (antiradiance_sweep.h's layout; with
/// a "pair" parameter two independent streams stacked).
engine::Result<RgbField> door_reference(const ReferenceJob& job);

inline glm::vec3 ref_at(const RgbField& f, std::size_t i) { return {f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]}; }

// The door moves on the CPU twin scored against the reference's changes: the field of every
// pose, the timings, and the change statistics (correlation sums and per-angle errors).
struct DoorMoveScores {
  std::vector<glm::vec3> values;
  std::vector<std::uint8_t> valid;
  // The projection floor: every pose's field with the true change passed through the leaves
  // (project_through_leaves) in place of the method's.
  std::vector<glm::vec3> floor_values;
  double move_ms = 0.0, solve_ms = 0.0, output_ms = 0.0;  // output: the change at the texels (gather or blend)
  double iterations = 0.0, residual = 0.0;  // mean iterations of the moves' solves, largest final residual
  double unconverged = 0.0;                 // moves whose solve ran out of its budget
  double so = 0.0, sr = 0.0, soo = 0.0, srr = 0.0, sor = 0.0, samples = 0.0;  // change correlation
  double level = 0.0;  // mean |E_ref(baked)| per channel over the compared texels
  std::vector<std::pair<std::string, double>> per_angle;

  void add_solve(const AntiradianceSolveReport& rep, std::size_t moves) {
    iterations += static_cast<double>(rep.iterations) / static_cast<double>(moves);
    residual = std::max(residual, rep.residual);
    unconverged += rep.budget_exhausted ? 1.0 : 0.0;
  }
  // Empty fields of every pose; the level of the baked truth.
  void start(const RgbField& reference, const DoorSetup& d) {
    const std::size_t n = d.texels.valid.size();
    values.assign(n * d.poses(), glm::vec3(0.0f));
    valid.assign(n * d.poses(), 0);
    floor_values.assign(n * d.poses(), glm::vec3(0.0f));
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t]) {
        const glm::vec3 e = ref_at(reference, t);
        level += static_cast<double>(e.x + e.y + e.z);
      }
    level /= 3.0 * static_cast<double>(d.compared);
  }
  // Pose k's field (the baked truth plus the change dt per texel) and its scores.
  void add_pose(const RgbField& reference, const DoorSetup& d, std::size_t k, const std::vector<glm::vec3>& dt) {
    const std::size_t n = d.texels.valid.size();
    double err2 = 0.0, change2 = 0.0, mean_o = 0.0, mean_r = 0.0;
    for (std::size_t t = 0; t < n; ++t) {
      if (!d.mask[t]) continue;
      const glm::vec3 base = ref_at(reference, t);
      values[k * n + t] = base + dt[t];
      valid[k * n + t] = 1;
      const glm::vec3 e = dt[t] - (ref_at(reference, k * n + t) - base);
      err2 += static_cast<double>(glm::dot(e, e));
      const glm::vec3 c = ref_at(reference, k * n + t) - base;
      change2 += static_cast<double>(glm::dot(c, c));
      for (int ch = 0; ch < 3; ++ch) {
        const double o = static_cast<double>(dt[t][ch]), r = static_cast<double>(c[ch]);
        mean_o += o, mean_r += r;
        so += o, sr += r, soo += o * o, srr += r * r, sor += o * r, samples += 1.0;
      }
    }
    const double nrmse = std::sqrt(err2 / (3.0 * static_cast<double>(d.compared))) / level;
    const int swing = static_cast<int>(d.swings[k - 1]);
    const std::string name = std::string(swing < 0 ? "m" : "p") + std::to_string(std::abs(swing));
    per_angle.emplace_back("change_nrmse_swing_" + name, nrmse);
    // What leaving the baked atlas unchanged scores by the same measure: the true change.
    per_angle.emplace_back("nothing_nrmse_swing_" + name,
                           std::sqrt(change2 / (3.0 * static_cast<double>(d.compared))) / level);
    // The mean over the compared texels (zone averages, as the corridor test compares them):
    // the true mean change and the error of the method's, both / level.
    const double count = 3.0 * static_cast<double>(d.compared);
    per_angle.emplace_back("true_mean_change_swing_" + name, mean_r / count / level);
    per_angle.emplace_back("mean_change_error_swing_" + name, (mean_o - mean_r) / count / level);
  }
  // Pose k's floor: the reference's true change through the leaves, on the baked pose's truth.
  void add_floor(const RgbField& reference, const DoorSetup& d, const std::vector<AntiradianceTexelBlend>& blends,
                 std::size_t leaves, std::size_t k) {
    const std::size_t n = d.texels.valid.size();
    std::vector<glm::vec3> true_change(n, glm::vec3(0.0f));
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t]) true_change[t] = ref_at(reference, k * n + t) - ref_at(reference, t);
    const std::vector<glm::vec3> floor = project_through_leaves(blends, true_change, d.mask, leaves);
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t]) floor_values[k * n + t] = ref_at(reference, t) + floor[t];
  }
};

// What changing nothing scores (the baked atlas left as it is) on the same texels: the
// field with every moved pose's compared texels set back to the reference's baked pose.
RgbField nothing_changed(const RgbField& field, const RgbField& reference, const DoorSetup& d);

// The run's change against the split truth (two references, `a` the one the run was scored
// against, `b` independent of it): the error and the correlation of the change with the
// references' noise removed (split_truth_change_score.h), as `split_*` extras. `field` holds
// the run's moved poses as the baked truth of `a` plus the run's change.
std::vector<std::pair<std::string, double>> split_truth_extras(const DoorSetup& d, const RgbField& field,
                                                               const RgbField& a, const RgbField& b);

}  // namespace gi::antiradiance_sweep
