#include "sweep/antiradiance_diagnosis_sweep.h"

#include <gi/error_metrics.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "antiradiance/antiradiance_direct_light.h"
#include "antiradiance/antiradiance_exact_transport.h"
#include "antiradiance/split_truth_change_score.h"

namespace gi::antiradiance_sweep {

// The knobs of the diagnosis (issue 37): the visibility-exact solver on the method's leaves
// (solve=exact) and the explicit visibility near the door (near_visibility).
std::vector<KnobSpec> exact_knobs() {
  return {
      {.name = "exact_pairs",
       .description = "solve=exact: Monte Carlo point pairs per leaf pair",
       .kind = KnobKind::Integer,
       .default_grid = {"64"},
       .min_value = 1,
       .max_value = 4096},
      {.name = "exact_bounces",
       .description = "solve=exact: indirect bounces (0: all, to the tolerance; 1: the first bounce only)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 64},
      {.name = "near_visibility",
       .description = "solve=on: the leaves within near_radius of the door's swept sphere (and the door's) gather "
                      "their light from every leaf with ray-traced visibility instead of antiradiance (exact_pairs "
                      "point pairs per leaf pair; blend output only)",
       .kind = KnobKind::Choice,
       .default_grid = {"off"},
       .choices = {"off", "on"}},
      {.name = "near_budget_mb",
       .description = "near_visibility: beyond near_radius, more receivers nearest the door while their rows fit "
                      "this many MiB (NearDoorVisibilitySettings::budget_bytes; the medium preset's 64 takes every "
                      "leaf of the corridor; 0: the radius alone)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 65536},
      {.name = "exact_adaptive",
       .description = "solve=exact: fewer point pairs for leaves smaller than patch^2 / 2 (ExactTransportSettings::"
                      "reference_area_m2)",
       .kind = KnobKind::Choice,
       .default_grid = {"off"},
       .choices = {"off", "on"}},
      {.name = "exact_noise",
       .description = "solve=exact: also solve with exact_seed + 1 and report the change's own noise (exact_noise_rel)",
       .kind = KnobKind::Choice,
       .default_grid = {"off"},
       .choices = {"off", "on"}},
      {.name = "exact_reuse",
       .description = "solve=exact and near_visibility: keep each point pair's visibility and trace at a door move "
                      "only the samples whose segment meets the door's boxes (ExactTransportSettings::"
                      "reuse_visibility; the same couplings; off above 64 exact_pairs)",
       .kind = KnobKind::Choice,
       .default_grid = {"on"},
       .choices = {"on", "off"}},
      {.name = "exact_seed",
       .description = "solve=exact: the point pairs' seed (two seeds measure the solver's own noise)",
       .kind = KnobKind::Integer,
       .default_grid = {"1"},
       .min_value = 1,
       .max_value = 1 << 30},
  };
}

// `--knob solve=off`: the leaves only, the field their projection floor (no solve needed:
// the true change passed through the leaves), with the leaf counts.
engine::Result<MethodOutput> run_projection_floor(const RunContext& ctx, const DoorSetup& d,
                                                  const AntiradianceSettings& s) {
  const auto t0 = Clock::now();
  auto h = build_element_hierarchy(d.input, s);
  if (!h) return h.error();
  const std::vector<AntiradianceTexelBlend> blends = antiradiance_texel_blends(*h, d.input, d.layout);
  MethodOutput out;
  out.costs.bake_seconds = ms_since(t0) / 1000.0;
  const std::size_t n = d.texels.valid.size();
  DoorMoveScores sc;
  sc.floor_values.assign(n * d.poses(), glm::vec3(0.0f));
  std::vector<std::uint8_t> valid(n * d.poses(), 0);
  for (std::size_t k = 1; k < d.poses(); ++k) {  // the moved poses, as score_door_moves compares them
    for (std::size_t t = 0; t < n; ++t) valid[k * n + t] = d.mask[t];
    sc.add_floor(ctx.reference, d, blends, h->leaf_count(), k);
  }
  out.field = RgbField::from_texels(d.texels.width, d.texels.height * static_cast<int>(d.poses()), sc.floor_values,
                                    std::move(valid));
  out.extras = {{"projection_floor_rel_rmse", compare_rgb(out.field, ctx.reference).rel_rmse},
                {"elements", static_cast<double>(h->nodes.size())},
                {"leaves", static_cast<double>(h->leaf_count())},
                {"compared_texels", static_cast<double>(d.compared)}};
  return out;
}

engine::Result<std::vector<std::pair<std::string, double>>> split_floor_extras(const DoorSetup& d,
                                                                               const AntiradianceSettings& s,
                                                                               const RgbField& a, const RgbField& b) {
  auto h = build_element_hierarchy(d.input, s);
  if (!h) return h.error();
  const std::vector<AntiradianceTexelBlend> blends = antiradiance_texel_blends(*h, d.input, d.layout);
  const std::size_t n = d.texels.valid.size();
  double truth_sq = 0.0, level = 0.0;  // as split_truth_extras: sum t^2 over the moved poses, the baked level
  for (std::size_t t = 0; t < n; ++t)
    if (d.mask[t]) level += 0.5 * static_cast<double>(glm::dot(ref_at(a, t) + ref_at(b, t), glm::vec3(1.0f)));
  level /= 3.0 * static_cast<double>(d.compared);
  SplitTruthFloor all;
  std::vector<std::pair<std::string, double>> per_angle;
  for (std::size_t k = 1; k < d.poses(); ++k) {
    std::vector<glm::vec3> mean(n, glm::vec3(0.0f)), half(n, glm::vec3(0.0f));
    for (std::size_t t = 0; t < n; ++t) {
      if (!d.mask[t]) continue;
      const glm::vec3 ca = ref_at(a, k * n + t) - ref_at(a, t), cb = ref_at(b, k * n + t) - ref_at(b, t);
      mean[t] = 0.5f * (ca + cb), half[t] = 0.5f * (ca - cb);
      truth_sq += static_cast<double>(glm::dot(ref_at(a, k * n + t), ref_at(b, k * n + t)));
    }
    const std::vector<glm::vec3> pm = project_through_leaves(blends, mean, d.mask, h->leaf_count());
    const std::vector<glm::vec3> ph = project_through_leaves(blends, half, d.mask, h->leaf_count());
    SplitTruthFloor pose;
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t])
        for (int c = 0; c < 3; ++c)
          pose.add(static_cast<double>(pm[t][c] - mean[t][c]), static_cast<double>(ph[t][c] - half[t][c]));
    all.merge(pose);
    const int swing = static_cast<int>(d.swings[k - 1]);
    const std::string name = std::string(swing < 0 ? "m" : "p") + std::to_string(std::abs(swing));
    per_angle.emplace_back("split_floor_nrmse_swing_" + name,
                           std::sqrt(std::max(0.0, pose.noise_removed_sse()) / std::max(pose.samples(), 1.0)) / level);
  }
  std::vector<std::pair<std::string, double>> extras = {
      {"split_floor_rel_rmse", std::sqrt(std::max(0.0, all.noise_removed_sse()) / truth_sq)},
      // The floor of the mean of the two references (its noise halved, not removed), and the
      // noise it carries: split_floor_rel_rmse^2 = the first^2 - the second^2.
      {"split_floor_of_mean_rel_rmse", std::sqrt((all.noise_removed_sse() + all.noise_sse()) / truth_sq)},
      {"split_floor_noise_rel_rmse", std::sqrt(all.noise_sse() / truth_sq)}};
  extras.insert(extras.end(), per_angle.begin(), per_angle.end());
  return extras;
}

namespace {

// One exact solver's door moves (`--knob solve=exact`): the change per leaf blended to the
// texels of every moved pose (poses 1.., texel-major as the fields), and what it cost.
struct ExactMoves {
  std::vector<std::vector<glm::vec3>> dt;  // [pose - 1][texel]
  double move_ms = 0.0, pairs = 0.0, rays = 0.0, iterations = 0.0, residual = 0.0, base_ms = 0.0;
  double base_pairs = 0.0;
};

engine::Result<ExactMoves> exact_door_moves(const RunContext& ctx, const DoorSetup& d, const AntiradianceSettings& s,
                                            std::uint64_t seed) {
  auto h = build_element_hierarchy(d.input, s);
  if (!h) return h.error();
  const std::vector<AntiradianceTexelBlend> blends = antiradiance_texel_blends(*h, d.input, d.layout);
  auto direct = AntiradianceDirectLight::create(d.input, s);
  if (!direct) return direct.error();
  ExactTransportSettings es;
  es.point_pairs = static_cast<int>(ctx.knobs.integer("exact_pairs"));
  if (ctx.knobs.text("exact_adaptive") == "on") es.reference_area_m2 = 0.5f * s.patch_size_m * s.patch_size_m;
  es.bounces = static_cast<int>(ctx.knobs.integer("exact_bounces"));
  es.tolerance = s.residual_tolerance > 0.0 ? s.residual_tolerance : 1e-3;
  es.seed = seed;
  es.reuse_visibility = ctx.knobs.text("exact_reuse") == "on" && es.point_pairs <= 64;
  auto transport = ExactLeafTransport::create(d.input, es);
  if (!transport) return transport.error();
  int group = -1;
  for (std::size_t g = 0; g < h->deforming_instances.size(); ++g)
    if (h->deforming_instances[g] == d.door) group = static_cast<int>(g + 1);
  if (group < 0) return engine::Error{.message = "the door is not a deforming group of the hierarchy"};
  ExactMoves out;
  const auto t0 = Clock::now();
  transport->update(*h);
  out.base_pairs = static_cast<double>(transport->last_pairs_computed());
  const ExactSolveResult base = transport->solve(*h, direct->update(*h));
  out.base_ms = ms_since(t0);
  const double moves = static_cast<double>(d.poses() - 1);
  for (std::size_t k = 1; k < d.poses(); ++k) {
    const glm::mat4 m = d.pose(d.swings[k - 1]);
    const auto t1 = Clock::now();
    h->set_group_transform(group, m);
    direct->set_instance_transform(d.door, m);
    transport->set_instance_transform(d.door, m);
    transport->update(*h);
    const ExactSolveResult e = transport->solve(*h, direct->update(*h));
    out.move_ms += ms_since(t1) / moves;
    out.pairs += static_cast<double>(transport->last_pairs_computed()) / moves;
    out.rays += static_cast<double>(transport->last_rays()) / moves;
    out.iterations += static_cast<double>(e.iterations) / moves;
    out.residual = std::max(out.residual, e.residual);
    std::vector<glm::vec3> delta(e.irradiance.size());
    for (std::size_t l = 0; l < delta.size(); ++l) delta[l] = e.irradiance[l] - base.irradiance[l];
    std::vector<glm::vec3> dt(d.texels.valid.size(), glm::vec3(0.0f));
    for (const AntiradianceTexelBlend& b : blends) dt[b.texel] = blend_leaves(b, delta);
    out.dt.push_back(std::move(dt));
    if (ctx.progress && !ctx.progress(0.1 + 0.4 * static_cast<double>(k) / moves))
      return engine::cancelled_error("antiradiance run");
  }
  return out;
}

}  // namespace

// `--knob solve=exact`: the visibility-exact solver on the method's leaves and direct light,
// scored like the method (its change through the same blend); `exact_seed` + 1 in a second
// solve when exact_noise is set gives the solver's own noise of the change.
engine::Result<MethodOutput> run_exact_transport(const RunContext& ctx, const DoorSetup& d,
                                                 const AntiradianceSettings& s) {
  const auto seed = static_cast<std::uint64_t>(ctx.knobs.integer("exact_seed"));
  auto a = exact_door_moves(ctx, d, s, seed);
  if (!a) return a.error();
  auto h = build_element_hierarchy(d.input, s);
  if (!h) return h.error();
  const std::vector<AntiradianceTexelBlend> blends = antiradiance_texel_blends(*h, d.input, d.layout);
  const std::size_t n = d.texels.valid.size();
  DoorMoveScores sc;
  sc.start(ctx.reference, d);
  for (std::size_t k = 1; k < d.poses(); ++k) {
    sc.add_floor(ctx.reference, d, blends, h->leaf_count(), k);
    sc.add_pose(ctx.reference, d, k, a->dt[k - 1]);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double noise = nan;
  if (ctx.knobs.text("exact_noise") == "on") {
    auto b = exact_door_moves(ctx, d, s, seed + 1);
    if (!b) return b.error();
    double sum = 0.0, count = 0.0;
    for (std::size_t k = 0; k < a->dt.size(); ++k)
      for (std::size_t t = 0; t < n; ++t)
        if (d.mask[t]) {
          const glm::vec3 e = a->dt[k][t] - b->dt[k][t];
          sum += static_cast<double>(glm::dot(e, e)), count += 3.0;
        }
    // The difference of two independent estimates has twice the variance of one.
    noise = std::sqrt(sum / count / 2.0) / sc.level;
  }
  const int poses = static_cast<int>(d.poses());
  MethodOutput out;
  out.costs.frame_ms = a->move_ms;
  out.costs.bake_seconds = a->base_ms / 1000.0;
  const RgbField floor_field =
      RgbField::from_texels(d.texels.width, d.texels.height * poses, sc.floor_values, sc.valid);
  out.field = RgbField::from_texels(d.texels.width, d.texels.height * poses, sc.values, std::move(sc.valid));
  const double cov = sc.sor - sc.so * sc.sr / sc.samples, var_o = sc.soo - sc.so * sc.so / sc.samples,
               var_r = sc.srr - sc.sr * sc.sr / sc.samples;
  out.extras = {{"nothing_rel_rmse", compare_rgb(nothing_changed(out.field, ctx.reference, d), ctx.reference).rel_rmse},
                {"change_correlation", var_o > 0.0 && var_r > 0.0 ? cov / std::sqrt(var_o * var_r) : nan},
                {"change_fit_scale", sc.soo > 0.0 ? sc.sor / sc.soo : nan},
                {"projection_floor_rel_rmse", compare_rgb(floor_field, ctx.reference).rel_rmse},
                {"exact_noise_rel", noise},
                {"solve_iterations", a->iterations},
                {"solve_residual_max", a->residual},
                {"exact_pairs_baked_pose", a->base_pairs},
                {"exact_pairs_per_move", a->pairs},
                {"exact_rays_per_move", a->rays}};
  out.extras.insert(out.extras.end(), sc.per_angle.begin(), sc.per_angle.end());
  out.extras.insert(out.extras.end(), {{"cpu_move_ms", a->move_ms},
                                       {"leaves", static_cast<double>(h->leaf_count())},
                                       {"compared_texels", static_cast<double>(d.compared)},
                                       {"level", sc.level}});
  return out;
}

}  // namespace gi::antiradiance_sweep
