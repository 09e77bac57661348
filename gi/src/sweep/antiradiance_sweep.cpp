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

#include "antiradiance/antiradiance_direct_light.h"
#include "antiradiance/antiradiance_exact_transport.h"
#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_io.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_texel_blend.h"
#include "antiradiance/antiradiance_texel_gather.h"
#include "antiradiance/near_door_visibility.h"
#include "antiradiance/split_truth_change_score.h"
#include "raytrace/atlas_reference.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi {
namespace {

// Other random streams than any bake's (see reference_sweep.cpp). The same for every pose,
// so a texel's paths that never meet the door are the same in every pose.
constexpr std::uint64_t kReferenceSeed = 0x616e746972616469ULL;

// Swings about the door's local Y from its authored (baked) pose, degrees. The corridor's
// door is authored at 50 degrees open: the sweep's poses are 0 (shut), 25 and 100; the knob
// `swings` scores other ones (issue 37's angle in no sweep: +25, the door at 75 degrees).
constexpr float kSweepSwings[] = {-50.0f, -25.0f, 50.0f};
constexpr const char* kSweepSwingsKey = "-50+-25+50";
const std::vector<std::string> kSwingChoices = {kSweepSwingsKey, "+25", "+10"};

// "-50+-25+50" -> {-50, -25, 50}; "+25" -> {25}.
std::vector<float> parse_swings(const std::string& key) {
  std::vector<float> out;
  std::size_t at = 0;
  while (at < key.size()) {
    std::size_t end = key.find('+', at);
    if (end == std::string::npos) end = key.size();
    if (end > at) out.push_back(std::stof(key.substr(at, end - at)));
    at = end + 1;
  }
  return out;
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

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

engine::Result<DoorSetup> door_setup(const SweepScene& scene, double density, double radius,
                                     const std::string& swings) {
  DoorSetup d;
  d.swings = parse_swings(swings);
  d.input = bake_input_from(scene.asset);
  bool found = false;
  for (std::size_t i = 0; i < d.input.instances.size() && !found; ++i)
    if (d.input.instances[i].deforming) {
      d.door = static_cast<std::uint32_t>(i);
      found = true;
    }
  if (!found) return engine::Error{.message = "the scene has no deforming instance (gi.region \"deforming\")"};
  d.authored = d.input.instances[d.door].object_to_world;
  const std::vector<AtlasInputMesh> inputs = atlas_inputs_from(d.input);
  auto layout = build_atlas_layout(inputs, {.texels_per_metre = static_cast<float>(density)});
  if (!layout) return layout.error();
  d.layout = std::move(layout).value();
  d.texels = rasterize_atlas(d.layout, inputs);
  // The door's swept bounds over the baked pose and the sweep's swings (whatever `swings`
  // scores, so that every run compares the same texels).
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
  const BakeMesh& mesh = d.input.meshes[d.input.instances[d.door].mesh];
  for (float swing : {0.0f, kSweepSwings[0], kSweepSwings[1], kSweepSwings[2]}) {
    const glm::mat4 m = d.pose(swing);
    for (const BakePrimitive& p : mesh.primitives)
      for (const glm::vec3& v : p.positions) {
        const glm::vec3 w(m * glm::vec4(v, 1.0f));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
  }
  std::vector<std::int32_t> static_instance;  // atlas input mesh -> BakeInput instance
  for (std::size_t i = 0; i < d.input.instances.size(); ++i)
    if (d.input.instances[i].mobility == BakeMobility::Static) static_instance.push_back(static_cast<std::int32_t>(i));
  d.mask.assign(d.texels.valid.size(), 0);
  for (std::size_t t = 0; t < d.texels.valid.size(); ++t) {
    if (!d.texels.valid[t] || d.texels.mesh[t] < 0 ||
        static_cast<std::size_t>(d.texels.mesh[t]) >= static_instance.size())
      continue;
    const auto inst = static_cast<std::size_t>(static_instance[static_cast<std::size_t>(d.texels.mesh[t])]);
    if (d.input.instances[inst].deforming) continue;
    const glm::vec3 p = d.texels.position[t];
    const glm::vec3 outside = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f));
    if (glm::length(outside) > static_cast<float>(radius)) continue;
    d.mask[t] = 1;
    ++d.compared;
  }
  if (d.compared == 0) return engine::Error{.message = "no static atlas texel lies within the radius of the door"};
  return d;
}

// One random stream's indirect irradiance at the compared texels of every pose, texel-major
// per pose; `part` of `parts` of the job's progress.
engine::Result<std::vector<glm::vec3>> door_truth_stream(const ReferenceJob& job, const DoorSetup& d,
                                                         std::uint64_t seed, int part, int parts) {
  const ReferenceRequest& r = job.request;
  AtlasTexels masked = d.texels;
  masked.valid = d.mask;
  const std::size_t n = masked.valid.size();
  const std::size_t poses = d.poses();
  std::vector<glm::vec3> values(n * poses, glm::vec3(0.0f));
  for (std::size_t k = 0; k < poses; ++k) {
    ReferenceSettings rs;
    rs.samples_per_pixel = std::stoi(r.param("spp"));
    rs.seed = seed;
    rs.threads = job.threads;
    if (!r.param("bounces").empty()) rs.max_bounces = std::stoi(r.param("bounces"));
    const ProgressFn& outer = job.progress;
    const double step = static_cast<double>(poses * static_cast<std::size_t>(parts));
    const double done = static_cast<double>(static_cast<std::size_t>(part) * poses + k);
    rs.progress = [&outer, done, step](double f) { return !outer || outer((done + f) / step); };
    auto truth = reference_atlas_irradiance(d.posed(k == 0 ? 0.0f : d.swings[k - 1]), masked, rs);
    if (!truth) return truth.error();
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t]) values[k * n + t] = truth->indirect[t];
  }
  return values;
}

// The door's reference: the sweep's stream (or `seed`'s), and with `pair` a second,
// independent stream (the one `seed` = pair gives) stacked below it: rows [0, h poses) the
// first, [h poses, 2 h poses) the second (the split truth of split_truth_change_score.h).
engine::Result<RgbField> door_reference(const ReferenceJob& job) {
  const ReferenceRequest& r = job.request;
  if (std::find(kSwingChoices.begin(), kSwingChoices.end(), r.param("swings")) == kSwingChoices.end())
    return engine::Error{"<sweep>", r.key(), "unknown swings"};
  auto d = door_setup(job.scene, std::stod(r.param("texels_per_m")), std::stod(r.param("radius")), r.param("swings"));
  if (!d) return engine::Error{"<sweep>", r.key(), d.error().message};
  const std::uint64_t seed = r.param("seed").empty() ? kReferenceSeed : kReferenceSeed ^ std::stoull(r.param("seed"));
  const bool paired = !r.param("pair").empty();
  const int parts = paired ? 2 : 1;
  auto values = door_truth_stream(job, *d, seed, 0, parts);
  if (!values) return values.error();
  if (paired) {
    auto second = door_truth_stream(job, *d, kReferenceSeed ^ std::stoull(r.param("pair")), 1, parts);
    if (!second) return second.error();
    values->insert(values->end(), second->begin(), second->end());
  }
  std::vector<std::uint8_t> valid;
  for (int p = 0; p < parts * static_cast<int>(d->poses()); ++p)
    valid.insert(valid.end(), d->mask.begin(), d->mask.end());
  const int height = d->texels.height * static_cast<int>(d->poses()) * parts;
  return RgbField::from_texels(d->texels.width, height, *values, std::move(valid));
}

// The shared headless GL context of the GPU timings (nullptr when none can be made).
const engine::GpuContext* gl_context() {
  static std::optional<engine::GpuContext> ctx = []() -> std::optional<engine::GpuContext> {
    auto c = engine::GpuContext::create_headless();
    if (!c) return std::nullopt;
    return std::move(c).value();
  }();
  return ctx ? &*ctx : nullptr;
}

glm::vec3 ref_at(const RgbField& f, std::size_t i) { return {f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]}; }

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

// `--knob near_visibility=on` (issue 37, off by default): the leaves near the door (its own,
// and the static ones within near_radius of its swept sphere) take their indirect light from
// every leaf through ray-traced visibility (form factors, ExactLeafTransport) instead of the
// antiradiance links: radiance only, every link of such a receiver tested; the other leaves
// keep the antiradiance solve's (NearDoorVisibility). Its change is this hybrid now minus at
// the baked pose.
struct NearVisibility {
  std::optional<NearDoorVisibility> near;
  std::size_t receivers = 0;
  double bake_ms = 0.0, move_ms = 0.0, rays = 0.0, pairs = 0.0;
  double update_ms = 0.0;   // of move_ms: the couplings' update (the rest: the receivers' solve)
  double iterations = 0.0;  // the receivers' solve, mean per move

  engine::Status init(const RunContext& ctx, const DoorSetup& d, AntiradianceRegion& region) {
    NearDoorVisibilitySettings ns;
    ns.radius_m = region.settings().near_radius_m;
    ns.point_pairs = static_cast<int>(ctx.knobs.integer("exact_pairs"));
    ns.seed = static_cast<std::uint64_t>(ctx.knobs.integer("exact_seed"));
    ns.reuse_visibility = ctx.knobs.text("exact_reuse") == "on" && ns.point_pairs <= 64;
    const auto t0 = Clock::now();
    region.update(false);  // the direct light at the baked pose
    auto n = NearDoorVisibility::create(d.input, region, d.door, ns);
    if (!n) return n.error();
    near.emplace(std::move(n).value());
    bake_ms = ms_since(t0);
    receivers = near->receivers();
    return {};
  }
  // After the region moved the door to `m` and solved: the hybrid's change per leaf.
  std::vector<glm::vec3> delta(const DoorSetup& d, const AntiradianceRegion& region, const glm::mat4& m,
                               std::size_t moves) {
    const auto t0 = Clock::now();
    std::vector<glm::vec3> e = near->move(region, d.door, m);
    move_ms += ms_since(t0) / static_cast<double>(moves);
    update_ms += near->last_update_ms() / static_cast<double>(moves);
    iterations += static_cast<double>(near->last_iterations()) / static_cast<double>(moves);
    rays += static_cast<double>(near->last_rays()) / static_cast<double>(moves);
    pairs += static_cast<double>(near->last_pairs()) / static_cast<double>(moves);
    for (std::size_t l = 0; l < e.size(); ++l) e[l] -= near->baseline()[l];
    return e;
  }
};

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
      for (const AntiradianceTexelBlend& b : blends) dt[b.texel] = blend_leaves(b, delta);
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

// What changing nothing scores (the baked atlas left as it is) on the same texels: the
// field with every moved pose's compared texels set back to the reference's baked pose.
RgbField nothing_changed(const RgbField& field, const RgbField& reference, const DoorSetup& d) {
  const std::size_t n = d.texels.valid.size();
  RgbField nothing = field;
  for (std::size_t k = 1; k < d.poses(); ++k)
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t])
        for (int c = 0; c < 3; ++c)
          nothing.rgb[3 * (k * n + t) + static_cast<std::size_t>(c)] =
              reference.rgb[3 * t + static_cast<std::size_t>(c)];
  return nothing;
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

// The run's change against the split truth (two references, `a` the one the run was scored
// against, `b` independent of it): the error and the correlation of the change with the
// references' noise removed (split_truth_change_score.h), as `split_*` extras. `field` holds
// the run's moved poses as the baked truth of `a` plus the run's change.
std::vector<std::pair<std::string, double>> split_truth_extras(const DoorSetup& d, const RgbField& field,
                                                               const RgbField& a, const RgbField& b) {
  const std::size_t n = d.texels.valid.size();
  SplitTruthChangeScore all, nothing;
  double truth_sq = 0.0, level = 0.0;  // sum over moved poses of t^2 (unbiased: a b), the baked level
  for (std::size_t t = 0; t < n; ++t)
    if (d.mask[t]) level += 0.5 * static_cast<double>(glm::dot(ref_at(a, t) + ref_at(b, t), glm::vec3(1.0f)));
  level /= 3.0 * static_cast<double>(d.compared);
  std::vector<std::pair<std::string, double>> per_angle;
  for (std::size_t k = 1; k < d.poses(); ++k) {
    SplitTruthChangeScore pose, pose_nothing;
    for (std::size_t t = 0; t < n; ++t) {
      if (!d.mask[t] || !field.is_valid(k * n + t)) continue;
      const glm::vec3 m = ref_at(field, k * n + t) - ref_at(a, t);
      const glm::vec3 ca = ref_at(a, k * n + t) - ref_at(a, t), cb = ref_at(b, k * n + t) - ref_at(b, t);
      truth_sq += static_cast<double>(glm::dot(ref_at(a, k * n + t), ref_at(b, k * n + t)));
      for (int c = 0; c < 3; ++c) {
        pose.add(static_cast<double>(m[c]), static_cast<double>(ca[c]), static_cast<double>(cb[c]));
        pose_nothing.add(0.0, static_cast<double>(ca[c]), static_cast<double>(cb[c]));
      }
    }
    all.merge(pose);
    nothing.merge(pose_nothing);
    const int swing = static_cast<int>(d.swings[k - 1]);
    const std::string name = std::string(swing < 0 ? "m" : "p") + std::to_string(std::abs(swing));
    const double count = std::max(pose.samples(), 1.0);
    per_angle.emplace_back("split_change_nrmse_swing_" + name,
                           std::sqrt(std::max(0.0, pose.noise_removed_sse()) / count) / level);
    per_angle.emplace_back("split_nothing_nrmse_swing_" + name,
                           std::sqrt(std::max(0.0, pose_nothing.noise_removed_sse()) / count) / level);
  }
  std::vector<std::pair<std::string, double>> extras = {
      // As rel_rmse (the run's error against the first reference), the noise removed.
      {"split_rel_rmse", std::sqrt(std::max(0.0, all.noise_removed_sse()) / truth_sq)},
      {"split_nothing_rel_rmse", std::sqrt(std::max(0.0, nothing.noise_removed_sse()) / truth_sq)},
      // The noise of one reference's change, in the same units (what the old columns include).
      {"split_ref_noise_rel_rmse", std::sqrt(all.noise_of_one() / truth_sq)},
      {"split_change_correlation", all.correlation_noise_removed()},
      {"split_change_correlation_raw", all.correlation_raw()},
      {"split_change_fit_scale", all.fit_scale()}};
  extras.insert(extras.end(), per_angle.begin(), per_angle.end());
  return extras;
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
  if (ctx.knobs.text("solve") != "off") {  // the floor's field carries the first reference's noise
    auto d = door_setup(ctx.scene, ctx.knobs.real("density"), ctx.knobs.real("radius"), ctx.knobs.text("swings"));
    if (!d) return d.error();
    for (auto& e : split_truth_extras(*d, out->field, a, b)) out->extras.push_back(std::move(e));
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
