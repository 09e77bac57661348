#include "sweep/antiradiance_sweep.h"

#include <gi/methods.h>

#include <GL/glcorearb.h>

#include <engine/gpu/context.h>
#include <gi/error_metrics.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_io.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_texel_blend.h"
#include "antiradiance/antiradiance_texel_gather.h"
#include "sweep/antiradiance_diagnosis_sweep.h"
#include "sweep/antiradiance_door_scoring.h"

namespace gi {
namespace {

using namespace antiradiance_sweep;  // the door, its references and scores; the diagnosis runs

// The shared headless GL context of the GPU timings (nullptr when none can be made).
const engine::GpuContext* gl_context() {
  static std::optional<engine::GpuContext> ctx = []() -> std::optional<engine::GpuContext> {
    auto c = engine::GpuContext::create_headless();
    if (!c) return std::nullopt;
    return std::move(c).value();
  }();
  return ctx ? &*ctx : nullptr;
}

// Long because it is one table: every knob of the method's bake and solve with its grid.
std::vector<KnobSpec> solve_knobs() {
  return {
      {.name = "patch",
       .description = "leaf element size: longest triangle-piece edge, metres (sets the hierarchy's depth)",
       .kind = KnobKind::Real,
       .default_grid = {"0.4", "0.6", "0.8"},
       .min_value = 0.05,
       .max_value = 10},
      {.name = "bins",
       .description = "octahedral bins per side (n x n directional bins)",
       .kind = KnobKind::Integer,
       .default_grid = {"6", "8", "11"},
       .min_value = 1,
       .max_value = 64},
      {.name = "iterations",
       .description = "iteration budget (global + push + local + pull each; asymmetric: radiance steps)",
       .kind = KnobKind::Integer,
       .default_grid = {"64"},
       .min_value = 1,
       .max_value = 256},
      {.name = "tolerance",
       .description = "residual tolerance of the solve (sum |dI_ex| / sum |I_ex|); 0: run the whole budget",
       .kind = KnobKind::Real,
       .default_grid = {"0.001"},
       .min_value = 0,
       .max_value = 1},
      {.name = "warm",
       .description = "a door move's solve starts from the previous pose's solution, converged when its residual "
                      "also dropped by this factor from its first iteration's (0: from the direct light)",
       .kind = KnobKind::Real,
       .default_grid = {"0.03"},
       .min_value = 0,
       .max_value = 1},
      {.name = "scheme",
       .description = "iteration of the paper's 2.2 (asymmetric: 4 antiradiance steps per radiance step)",
       .kind = KnobKind::Choice,
       .default_grid = {"symmetric"},
       .choices = {"symmetric", "asymmetric"}},
      {.name = "oracle",
       .description = "link oracle scale (x the smallest bin solid angle; 1: the paper's rule)",
       .kind = KnobKind::Real,
       .default_grid = {"1"},
       .min_value = 0.01,
       .max_value = 100},
      {.name = "near_patch",
       .description = "adaptive leaves: leaf size within near_radius of the door's swept sphere and on the door, "
                      "metres (0: off, patch everywhere)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 10},
      {.name = "near_radius",
       .description = "adaptive leaves and precise near links: how far from the door's swept sphere the leaves are "
                      "near_patch and links precise, metres",
       .kind = KnobKind::Real,
       .default_grid = {"1"},
       .min_value = 0,
       .max_value = 100},
      {.name = "pieces",
       .description = "leaf-leaf links that fail the oracle: virtual pieces per end at most (0: linked regardless)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 4096},
      {.name = "near_samples",
       .description = "precise near links: pieces per oracle solid angle on links with an end on the door or "
                      "within near_radius of its swept sphere (0: off; link_mesh.h)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1024},
      {.name = "near_max_pieces",
       .description = "precise near links: pieces per end at most",
       .kind = KnobKind::Integer,
       .default_grid = {"256"},
       .min_value = 1,
       .max_value = 4096},
      {.name = "solve",
       .description = "off: build the leaves only and score the projection floor (the true change through them) as "
                      "the field; exact: the same leaves and direct light, transport by form factors with ray-traced "
                      "visibility (antiradiance_exact_transport.h, diagnosis only)",
       .kind = KnobKind::Choice,
       .default_grid = {"on"},
       .choices = {"on", "off", "exact"}},
      {.name = "output",
       .description = "how the change reaches a texel: blend (the runtime's 4 nearest leaves) or gather (from the "
                      "hierarchy at the texel, antiradiance_texel_gather.h)",
       .kind = KnobKind::Choice,
       .default_grid = {"blend"},
       .choices = {"blend", "gather"}},
      {.name = "gpu",
       .description = "also time the door move with the GPU passes (compute shaders; headless GL)",
       .kind = KnobKind::Choice,
       .default_grid = {"on"},
       .choices = {"on", "off"}},
  };
}

// The knobs of what is scored: where and at which door angles, against how many samples.
std::vector<KnobSpec> scoring_knobs() {
  return {
      {.name = "density",
       .description = "atlas texels per metre where the change is compared",
       .kind = KnobKind::Real,
       .default_grid = {"8"},
       .min_value = 0.01,
       .max_value = 1e4},
      {.name = "radius",
       .description = "compared texels lie within this many metres of the door's swept bounds",
       .kind = KnobKind::Real,
       .default_grid = {"1"},
       .min_value = 0,
       .max_value = 1e4},
      {.name = "swings",
       .description = "the door's moves scored, degrees from its baked pose joined by '+' (the corridor's door is "
                      "baked at 50: -50+-25+50 are 0, 25 and 100 degrees; +25 is 75, +10 is 60)",
       .kind = KnobKind::Choice,
       .default_grid = {kSweepSwingsKey},
       .choices = kSwingChoices},
      {.name = "ref_spp",
       .description = "samples per texel and pose of the path-traced reference",
       .kind = KnobKind::Integer,
       .default_grid = {"4096"},
       .min_value = 1,
       .max_value = 1 << 20},
      {.name = "ref_seed",
       .description = "another random stream for the reference (0: the sweep's; k: an independent estimate, to "
                      "measure the reference's own noise)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1 << 30},
      {.name = "ref_pair",
       .description = "the split truth: a second, independent reference (the stream ref_seed = ref_pair gives) "
                      "rendered with the first, and the change scored with the references' noise removed "
                      "(split_* columns; 0: one reference only)",
       .kind = KnobKind::Integer,
       .default_grid = {"7"},
       .min_value = 0,
       .max_value = 1 << 30},
      {.name = "ref_bounces",
       .description = "indirect bounces of the reference (0: all; 1: the first bounce off directly lit surfaces)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 64},
  };
}

std::vector<KnobSpec> antiradiance_knobs() {
  std::vector<KnobSpec> knobs = solve_knobs();
  for (KnobSpec& k : exact_knobs()) knobs.push_back(std::move(k));
  for (KnobSpec& k : scoring_knobs()) knobs.push_back(std::move(k));
  return knobs;
}

ReferenceRequest door_reference_request(const SweepScene&, const KnobSetting& k) {
  ReferenceRequest r;
  r.kind = "atlas_indirect_irradiance_door";
  r.params = {{"texels_per_m", k.text("density")},
              {"radius", k.text("radius")},
              {"spp", std::to_string(k.integer("ref_spp"))},
              {"swings", k.text("swings")}};
  // Only a bounded reference names its bounces, so the full ones keep their cache keys.
  if (k.integer("ref_bounces") > 0) r.params.emplace_back("bounces", std::to_string(k.integer("ref_bounces")));
  if (k.integer("ref_seed") > 0) r.params.emplace_back("seed", std::to_string(k.integer("ref_seed")));
  if (k.integer("ref_pair") > 0) r.params.emplace_back("pair", std::to_string(k.integer("ref_pair")));
  return r;
}

AntiradianceSettings antiradiance_settings(const RunContext& ctx) {
  AntiradianceSettings s;
  s.patch_size_m = static_cast<float>(ctx.knobs.real("patch"));
  s.bins_per_side = static_cast<int>(ctx.knobs.integer("bins"));
  s.iterations = static_cast<int>(ctx.knobs.integer("iterations"));
  s.residual_tolerance = ctx.knobs.real("tolerance");
  s.warm_start = ctx.knobs.real("warm") > 0.0;
  s.warm_tolerance = ctx.knobs.real("warm");
  s.scheme = ctx.knobs.text("scheme") == "asymmetric" ? AntiradianceScheme::Asymmetric : AntiradianceScheme::Symmetric;
  s.oracle_scale = static_cast<float>(ctx.knobs.real("oracle"));
  s.near_patch_size_m = static_cast<float>(ctx.knobs.real("near_patch"));
  s.near_radius_m = static_cast<float>(ctx.knobs.real("near_radius"));
  s.leaf_link_pieces = static_cast<int>(ctx.knobs.integer("pieces"));
  s.near_link_samples = static_cast<int>(ctx.knobs.integer("near_samples"));
  s.near_link_max_pieces = static_cast<int>(ctx.knobs.integer("near_max_pieces"));
  s.seed = ctx.seed;
  return s;
}

// What the bundle stores: the size of antiradiance.bin as gi-bake writes it (`unique` names
// the temporary file apart from concurrent runs').
engine::Result<std::uint64_t> stored_bytes(const AntiradianceBake& bake, std::uint64_t seed, const void* unique) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("gi-sweep-antiradiance-" + std::to_string(seed) + "-" +
                                                std::to_string(reinterpret_cast<std::uintptr_t>(unique)) + ".bin");
  if (engine::Status st = write_antiradiance(file, bake, "sweep"); !st) return st.error();
  std::error_code ec;
  const auto bytes = static_cast<std::uint64_t>(std::filesystem::file_size(file, ec));
  std::filesystem::remove(file, ec);
  return bytes;
}

// The change at the compared texels: blended from the leaves' delta (the runtime's), or
// gathered at the texels from the solved hierarchy minus the same gather at the baked pose.
struct TexelOutput {
  bool gather = false;
  std::vector<GatherPoint> points;
  std::vector<std::size_t> texel;   // per point
  std::vector<glm::vec3> baseline;  // gathered at the baked pose

  // Solves the region at its (baked) pose and gathers there.
  TexelOutput(const DoorSetup& d, AntiradianceRegion& region, bool gather_at_texels) : gather(gather_at_texels) {
    if (!gather) return;
    for (std::size_t t = 0; t < d.mask.size(); ++t)
      if (d.mask[t]) {
        points.push_back({d.texels.position[t], d.texels.normal[t]});
        texel.push_back(t);
      }
    region.update(true);
    baseline = gather_at_points(region.hierarchy(), region.bins(), region.settings(), region.exitant(), points);
  }

  std::vector<glm::vec3> change(const AntiradianceRegion& region, const std::vector<AntiradianceTexelBlend>& blends,
                                std::size_t n) const {
    std::vector<glm::vec3> dt(n, glm::vec3(0.0f));
    if (!gather) {
      const std::vector<glm::vec3> delta = region.delta(region.irradiance());
      for (const AntiradianceTexelBlend& b : blends) dt[b.texel] = blend_leaves(b, delta);
      return dt;
    }
    const std::vector<glm::vec3> e =
        gather_at_points(region.hierarchy(), region.bins(), region.settings(), region.exitant(), points);
    for (std::size_t i = 0; i < points.size(); ++i) dt[texel[i]] = e[i] - baseline[i];
    return dt;
  }
};

// The change the runtime's composite makes at each blended texel (composite_change), with the
// baked truth standing for the atlas it is composited into: what the renderer adds.
// `share` per leaf (empty: 0 everywhere, antiradiance's own leaves).
void composite_at_texels(const RgbField& reference, const std::vector<AntiradianceTexelBlend>& blends,
                         const std::vector<glm::vec3>& delta, const std::vector<glm::vec3>& baseline,
                         const std::vector<char>& share, std::vector<glm::vec3>& dt) {
  for (const AntiradianceTexelBlend& b : blends) {
    const glm::vec3 atlas = ref_at(reference, b.texel);
    float s = 0.0f;
    for (int k = 0; k < 4; ++k)
      if (b.leaves[k] >= 0 && static_cast<std::size_t>(b.leaves[k]) < share.size() &&
          share[static_cast<std::size_t>(b.leaves[k])])
        s += b.weights[k];
    dt[b.texel] = composite_change(atlas, blend_leaves(b, delta), blend_leaves(b, baseline), s) - atlas;
  }
}

// Each door move on the CPU twin: relink + direct light (update(false)), then the solve.
engine::Result<DoorMoveScores> score_door_moves(const RunContext& ctx, const DoorSetup& d, AntiradianceRegion& region,
                                                const std::vector<AntiradianceTexelBlend>& blends,
                                                const TexelOutput& output, NearVisibility* near) {
  const std::size_t n = d.texels.valid.size();
  DoorMoveScores s;
  const std::size_t poses = d.poses();
  s.start(ctx.reference, d);
  for (std::size_t k = 1; k < poses; ++k) {
    region.set_instance_transform(d.door, d.pose(d.swings[k - 1]));
    const auto t0 = Clock::now();
    region.update(false);
    s.move_ms += ms_since(t0);
    const auto t1 = Clock::now();
    const AntiradianceSolveReport rep = region.update(true);  // nothing moved since: the solve only
    s.solve_ms += ms_since(t1);
    s.add_solve(rep, poses - 1);
    const auto t2 = Clock::now();
    std::vector<glm::vec3> dt = output.change(region, blends, n);
    s.output_ms += ms_since(t2);
    if (near) {
      const std::vector<glm::vec3> delta = near->delta(d, region, d.pose(d.swings[k - 1]), poses - 1);
      composite_at_texels(ctx.reference, blends, delta, near->near->baseline(), near->near->receiver_mask(), dt);
    }
    s.add_floor(ctx.reference, d, blends, region.hierarchy().leaf_count(), k);
    s.add_pose(ctx.reference, d, k, dt);
    if (ctx.progress && !ctx.progress(0.3 + 0.5 * static_cast<double>(k) / static_cast<double>(poses - 1)))
      return engine::cancelled_error("antiradiance run");
  }
  return s;
}

// The GPU's door move: its time, its buffers' bytes and its largest difference from the CPU
// twin (relative to the largest CPU irradiance). NaN each when no GPU pass can be made.
struct GpuDoorMove {
  double ms = std::numeric_limits<double>::quiet_NaN();
  double bytes = std::numeric_limits<double>::quiet_NaN();
  double cpu_diff = std::numeric_limits<double>::quiet_NaN();
};

engine::Result<GpuDoorMove> time_gpu_door_move(const DoorSetup& d, AntiradianceRegion& region) {
  GpuDoorMove g;
  const engine::GpuContext* gl = gl_context();
  if (!gl) return g;
  gl->make_current();
  auto gpu = AntiradianceGpuPass::create(region.hierarchy(), region.bins(), region.links());
  if (!gpu) return g;  // above the SSBO limit (or no compute shaders): the GPU columns stay empty
  // The runtime's door move (AntiradianceLighting::update): relink + direct light on
  // the CPU, link upload, the iteration, the result read back; back to the first swing.
  region.set_instance_transform(d.door, d.pose(d.swings[0]));
  const auto t0 = Clock::now();
  region.update(false);
  if (engine::Status st = gpu->set_links(region.links()); !st) return st.error();
  const AntiradianceSolveReport rep = run_antiradiance(*gpu, region.direct(), region.settings(), region.hierarchy());
  std::vector<glm::vec3> e = gpu->irradiance();
  glFinish();
  g.ms = ms_since(t0);
  g.bytes = static_cast<double>(gpu->gpu_bytes());
  region.discard_solution();  // the fresh GPU pass started from the direct light: so does the twin
  region.update(true);
  const std::vector<glm::vec3> cpu = region.irradiance();
  double diff = 0.0, scale = 0.0;
  for (std::size_t l = 0; l < e.size() && l < cpu.size(); ++l) {
    diff = std::max(diff, static_cast<double>(glm::length(rep.output_scale * e[l] - cpu[l])));
    scale = std::max(scale, static_cast<double>(glm::length(cpu[l])));
  }
  g.cpu_diff = scale > 0.0 ? diff / scale : 0.0;
  return g;
}

// The run's extras: the change statistics, the floor, the solves, the costs and sizes.
std::vector<std::pair<std::string, double>> door_move_extras(const RunContext& ctx, const DoorSetup& d,
                                                             const AntiradianceRegion& region, const DoorMoveScores& sc,
                                                             const GpuDoorMove& gpu, const RgbField& field,
                                                             const RgbField& floor_field) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double moves = static_cast<double>(d.poses() - 1);
  const double samples = sc.samples;
  const double cov = sc.sor - sc.so * sc.sr / samples, var_o = sc.soo - sc.so * sc.so / samples,
               var_r = sc.srr - sc.sr * sc.sr / samples;
  std::vector<std::pair<std::string, double>> extras = {
      {"nothing_rel_rmse", compare_rgb(nothing_changed(field, ctx.reference, d), ctx.reference).rel_rmse},
      {"change_correlation", var_o > 0.0 && var_r > 0.0 ? cov / std::sqrt(var_o * var_r) : nan},
      {"change_fit_scale", sc.soo > 0.0 ? sc.sor / sc.soo : nan},
      // The rel. RMSE of the true change passed through the leaves: what the per-leaf output
      // cannot go below, whatever the solver (project_through_leaves).
      {"projection_floor_rel_rmse", compare_rgb(floor_field, ctx.reference).rel_rmse},
      {"solve_iterations", sc.iterations},
      {"solve_residual_max", sc.residual},
      {"solve_unconverged", sc.unconverged}};
  extras.insert(extras.end(), sc.per_angle.begin(), sc.per_angle.end());
  extras.insert(extras.end(), {{"cpu_move_ms", sc.move_ms / moves},
                               {"cpu_solve_ms", sc.solve_ms / moves},
                               {"cpu_output_ms", sc.output_ms / moves},
                               {"gpu_frame_ms", gpu.ms},
                               {"gpu_bytes", gpu.bytes},
                               {"gpu_cpu_rel_diff", gpu.cpu_diff},
                               {"elements", static_cast<double>(region.hierarchy().nodes.size())},
                               {"leaves", static_cast<double>(region.hierarchy().leaf_count())},
                               {"links", static_cast<double>(region.links().links.size())},
                               // The last move's relink: directed precise near links and their piece pairs.
                               {"precise_links", static_cast<double>(region.links().precise_links)},
                               {"precise_piece_pairs", static_cast<double>(region.links().precise_piece_pairs)},
                               {"compared_texels", static_cast<double>(d.compared)},
                               {"level", sc.level}});
  return extras;
}

engine::Result<MethodOutput> run_on_one_truth(const RunContext& ctx) {
  auto d = door_setup(ctx.scene, ctx.knobs.real("density"), ctx.knobs.real("radius"), ctx.knobs.text("swings"));
  if (!d) return d.error();
  const int poses = static_cast<int>(d->poses());
  if (ctx.reference.width != d->texels.width || ctx.reference.height != d->texels.height * poses)
    return engine::Error{.message = "the atlas size differs from the reference's"};
  const AntiradianceSettings s = antiradiance_settings(ctx);
  if (ctx.knobs.text("solve") == "off") return run_projection_floor(ctx, *d, s);
  if (ctx.knobs.text("solve") == "exact") return run_exact_transport(ctx, *d, s);

  const auto t_bake = Clock::now();
  auto bake = bake_antiradiance(d->input, s);
  if (!bake) return bake.error();
  MethodOutput out;
  out.costs.bake_seconds = ms_since(t_bake) / 1000.0;
  if (ctx.progress && !ctx.progress(0.3)) return engine::cancelled_error("antiradiance run");
  auto bytes = stored_bytes(*bake, ctx.seed, &out);
  if (!bytes) return bytes.error();
  out.costs.bytes = *bytes;
  auto region = AntiradianceRegion::create(d->input, std::move(bake).value());
  if (!region) return region.error();
  const std::vector<AntiradianceTexelBlend> blends =
      antiradiance_texel_blends(region->hierarchy(), d->input, d->layout);

  const TexelOutput output(*d, *region, ctx.knobs.text("output") == "gather");
  NearVisibility near;
  const bool near_on = ctx.knobs.text("near_visibility") == "on";
  if (near_on)
    if (engine::Status st = near.init(ctx, *d, *region); !st) return st.error();
  auto scores = score_door_moves(ctx, *d, *region, blends, output, near_on ? &near : nullptr);
  if (!scores) return scores.error();
  DoorMoveScores& sc = *scores;
  const double moves = static_cast<double>(poses - 1);
  out.costs.frame_ms = (sc.move_ms + sc.solve_ms + (output.gather ? sc.output_ms : 0.0)) / moves;
  const RgbField floor_field =
      RgbField::from_texels(d->texels.width, d->texels.height * poses, sc.floor_values, sc.valid);
  out.field = RgbField::from_texels(d->texels.width, d->texels.height * poses, sc.values, std::move(sc.valid));

  GpuDoorMove gpu;
  if (ctx.knobs.text("gpu") == "on") {
    auto timed = time_gpu_door_move(*d, *region);
    if (!timed) return timed.error();
    gpu = *timed;
  }
  out.extras = door_move_extras(ctx, *d, *region, sc, gpu, out.field, floor_field);
  if (near_on) {
    out.costs.frame_ms += near.move_ms;
    out.extras.insert(out.extras.end(), {{"near_visibility_receivers", static_cast<double>(near.receivers)},
                                         {"near_visibility_bake_ms", near.bake_ms},
                                         {"near_visibility_move_ms", near.move_ms},
                                         {"near_visibility_update_ms", near.update_ms},
                                         {"near_visibility_iterations", near.iterations},
                                         {"near_visibility_pairs_per_move", near.pairs},
                                         {"near_visibility_rays_per_move", near.rays}});
  }
  return out;
}

// A run: scored against the first reference as always; with `ref_pair` the reference holds
// a second one below it (door_reference), and the split truth's scores join the extras.
engine::Result<MethodOutput> run_door_moves(const RunContext& ctx) {
  if (ctx.knobs.integer("ref_pair") == 0) return run_on_one_truth(ctx);
  if (ctx.knobs.integer("ref_pair") == ctx.knobs.integer("ref_seed"))
    return engine::Error{.message = "ref_pair must name another stream than ref_seed"};
  const RgbField& both = ctx.reference;
  if (both.height % 2 != 0 || both.valid.size() != both.count())
    return engine::Error{.message = "the paired reference is not two masked halves"};
  RgbField a, b;
  for (RgbField* half : {&a, &b}) {
    const std::size_t offset = half == &a ? 0 : both.count() / 2;
    half->width = both.width;
    half->height = both.height / 2;
    half->rgb.assign(both.rgb.begin() + static_cast<std::ptrdiff_t>(3 * offset),
                     both.rgb.begin() + static_cast<std::ptrdiff_t>(3 * (offset + half->count())));
    half->valid.assign(both.valid.begin() + static_cast<std::ptrdiff_t>(offset),
                       both.valid.begin() + static_cast<std::ptrdiff_t>(offset + half->count()));
  }
  const RunContext first{.scene = ctx.scene,
                         .knobs = ctx.knobs,
                         .request = ctx.request,
                         .reference = a,
                         .seed = ctx.seed,
                         .threads = ctx.threads,
                         .progress = ctx.progress,
                         .split_truth = ctx.split_truth};
  auto out = run_on_one_truth(first);
  if (!out) return out;
  auto d = door_setup(ctx.scene, ctx.knobs.real("density"), ctx.knobs.real("radius"), ctx.knobs.text("swings"));
  if (!d) return d.error();
  if (ctx.knobs.text("solve") != "off") {  // the floor's field carries the first reference's noise
    for (auto& e : split_truth_extras(*d, out->field, a, b)) out->extras.push_back(std::move(e));
  } else {  // its own split: the floor with the noise removed
    auto floor = split_floor_extras(*d, antiradiance_settings(ctx), a, b);
    if (!floor) return floor.error();
    for (auto& e : *floor) out->extras.push_back(std::move(e));
  }
  // The output in the reference's layout: the second half is not the run's to match.
  if (out->field.valid.empty()) out->field.valid.assign(out->field.count(), 1);
  out->field.height *= 2;
  out->field.rgb.resize(3 * out->field.count(), 0.0f);
  out->field.valid.resize(out->field.count(), 0);
  return out;
}

}  // namespace

void register_antiradiance_sweep(SweepRegistry& registry) {
  registry.add_reference_provider(
      {.kind = "atlas_indirect_irradiance_door", .version = "pt-1", .compute = door_reference});

  SweepMethod m;
  m.name = method_descriptor(EffectMethod::Antiradiance).key;  // gi/methods.h
  m.description =
      "antiradiance (Dachsbacher 2007): element size x bins x iterations vs the path-traced change of indirect "
      "irradiance when the deforming node swings -50, -25, +50 degrees from its baked pose";
  m.knobs = antiradiance_knobs();
  m.reference_for = door_reference_request;
  m.run = run_door_moves;
  registry.add_method(std::move(m));
}

}  // namespace gi
