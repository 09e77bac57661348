#include "sweep/prm_sweep.h"

#include <gi/methods.h>

#include <engine/scene.h>
#include <gi/error_metrics.h>
#include <gi/reference.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <glm/gtc/quaternion.hpp>

#include "core/color.h"
#include "prm/pane_upsample.h"
#include "prm/prm.h"
#include "prm/prm_runtime.h"
#include "raytrace/atlas_reference.h"
#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi {
namespace {

constexpr std::uint64_t kReferenceSeed = 0x7072656665726e63ULL;

// The axis-aligned bounds of the static surfaces, metres.
std::pair<glm::vec3, glm::vec3> static_bounds(const engine::SceneAsset& asset) {
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
  for (const AtlasInputMesh& m : atlas_inputs_from(bake_input_from(asset)))
    for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  return {lo, hi};
}

}  // namespace

engine::Result<glm::vec3> moved_light_position(const engine::SceneAsset& asset, const glm::vec3& authored,
                                               const std::string& pose) {
  if (pose == "along") {
    const auto [lo, hi] = static_bounds(asset);
    return authored + glm::vec3(0.3f * (hi.x - lo.x), 0.0f, 0.0f);
  }
  if (pose != "wall20") return engine::Error{.message = "unknown light pose '" + pose + "' (along, wall20)"};
  auto caster = make_static_caster(bake_input_from(asset));
  if (!caster) return caster.error();
  Hit nearest;
  glm::vec3 towards(0.0f);
  for (const glm::vec3 d : {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 0, -1)}) {
    const Hit h = (*caster)->intersect(Ray{.origin = authored, .direction = d});
    if (h.valid() && h.t < nearest.t) nearest = h, towards = d;
  }
  if (!nearest.valid() || nearest.t <= 0.2f)
    return engine::Error{.message = "pose wall20: no static surface more than 20 cm away horizontally"};
  return authored + (nearest.t - 0.2f) * towards;
}

namespace {

// The scene with only its moving light on (the first light flagged as moving, else the
// first light; every other light off and every emissive material dark, since the PRM relights
// only the moving light and emissive surfaces belong to the static-light atlas), flagged as
// moving, at `pose`, then swung by `swing_deg` degrees about Z the
// way the demo's swinging lamp moves (gameplay.cpp swing_lamp): a light with a parent node
// (a pivot) turns its parent, rest rotation x angleAxis(swing, local Z); a light without one
// turns about the world Z axis through its own position (a spot's beam sweeps across the
// room). Poses "along" and "wall20" start from the authored position (moved_light_position):
// for levels where "corner" and "wall", placed in the static bounds, land inside walls or
// outside the building (Sponza). Errors: no light, unknown pose.
engine::Result<engine::Scene> posed_scene(engine::SceneAsset asset, const std::string& pose, double swing_deg = 0.0) {
  int chosen = -1;
  for (std::size_t n = 0; n < asset.nodes.size() && chosen < 0; ++n) {
    const int l = asset.nodes[n].light;
    if (l >= 0 && static_cast<std::size_t>(l) < asset.lights.size() &&
        asset.lights[static_cast<std::size_t>(l)].light.moves)
      chosen = static_cast<int>(n);
  }
  for (std::size_t n = 0; n < asset.nodes.size() && chosen < 0; ++n)
    if (asset.nodes[n].light >= 0) chosen = static_cast<int>(n);
  if (chosen < 0) return engine::Error{.message = "the scene has no light to move"};
  for (engine::NamedLight& l : asset.lights) l.light.enabled = false;
  for (auto& m : asset.materials) m.emissive = glm::vec3(0.0f);
  engine::Node& node = asset.nodes[static_cast<std::size_t>(chosen)];
  engine::Light& light = asset.lights[static_cast<std::size_t>(node.light)].light;
  light.enabled = true;
  light.moves = true;
  if (pose != "authored") {
    const auto [lo, hi] = static_bounds(asset);
    const glm::vec3 size = hi - lo, centre = 0.5f * (lo + hi);
    glm::vec3 position, direction;
    if (pose == "along" || pose == "wall20") {
      if (node.parent >= 0)
        return engine::Error{.message = "the moving light has a parent node; pose it in world space first"};
      auto at = moved_light_position(asset, node.translation, pose);
      if (!at) return at.error();
      position = *at;
      direction = glm::vec3(0.0f, -1.0f, 0.0f);
    } else if (pose == "corner") {
      position = lo + glm::vec3(0.15f, 0.3f, 0.15f) * size;
      direction = glm::normalize(centre - position);
    } else if (pose == "wall") {
      // A lamp held against a wall, shining down along it: the wall gets grazing light from
      // 1 cm away (pointing it into the wall would put all light into a spot of millimetres,
      // which the path-traced reference cannot resolve either).
      position = glm::vec3(hi.x - 0.01f, centre.y, centre.z);
      direction = glm::vec3(0.0f, -1.0f, 0.0f);
    } else {
      return engine::Error{.message = "unknown light pose '" + pose + "' (authored, corner, wall, along, wall20)"};
    }
    if (node.parent >= 0)
      return engine::Error{.message = "the moving light has a parent node; pose it in world space first"};
    node.translation = position;
    // Lights shine along their local -Z.
    node.rotation =
        glm::quatLookAtRH(direction, std::abs(direction.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0));
  }
  if (swing_deg != 0.0) {
    const glm::quat turn = glm::angleAxis(static_cast<float>(glm::radians(swing_deg)), glm::vec3(0, 0, 1));
    if (node.parent >= 0) {
      engine::Node& pivot = asset.nodes[static_cast<std::size_t>(node.parent)];
      pivot.rotation = pivot.rotation * turn;
    } else {
      node.rotation = turn * node.rotation;
    }
  }
  return engine::instantiate(std::move(asset));
}

// The reference's world: every instance ("all"), or the static ones only ("static": what the
// PRM's entry points, panes and shadow rays model; dynamic meshes such as the demo's lamp shade
// or its crates then neither occlude nor reflect in the reference either).
BakeInput reference_world(BakeInput input, const std::string& world) {
  if (world == "static")
    std::erase_if(input.instances, [](const BakeInstance& i) { return i.mobility == BakeMobility::Dynamic; });
  return input;
}

// splitmix64: a fixed, portable stream (std::shuffle's draws differ between libraries).
std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

void keep_random_texels(AtlasTexels& texels, std::uint64_t count) {
  std::vector<std::size_t> valid;
  for (std::size_t i = 0; i < texels.valid.size(); ++i)
    if (texels.valid[i] != 0) valid.push_back(i);
  if (count >= valid.size()) return;
  // The first `count` of a partial Fisher-Yates shuffle.
  std::uint64_t state = kReferenceSeed;
  for (std::size_t i = 0; i < count; ++i)
    std::swap(valid[i], valid[i + static_cast<std::size_t>(splitmix64(state) % (valid.size() - i))]);
  for (std::size_t i = count; i < valid.size(); ++i) texels.valid[valid[i]] = 0;
}

namespace {

engine::Result<RgbField> prm_reference(const ReferenceJob& job) {
  const std::string swing = job.request.param("swing");
  auto scene = posed_scene(job.scene.asset, job.request.param("pose"), swing.empty() ? 0.0 : std::stod(swing));
  if (!scene) return scene.error();
  const auto inputs = atlas_inputs_from(bake_input_from(job.scene.asset));
  auto layout = build_atlas_layout(inputs, {.texels_per_metre = std::stof(job.request.param("texels_per_m"))});
  if (!layout) return layout.error();
  ReferenceSettings rs;
  rs.samples_per_pixel = std::stoi(job.request.param("spp"));
  rs.seed = kReferenceSeed;
  rs.threads = job.threads;
  rs.progress = job.progress;
  const std::string world = job.request.param("world"), subset = job.request.param("texels");
  AtlasTexels texels = rasterize_atlas(*layout, inputs);
  if (!subset.empty()) keep_random_texels(texels, std::stoull(subset));
  auto truth =
      reference_atlas_irradiance(reference_world(bake_input_from(*scene), world.empty() ? "all" : world), texels, rs);
  if (!truth) return truth.error();
  // With its sampling variance, so that the sweep reports the error against the noise-free
  // truth (error_metrics.h) beside the error against this reference.
  return RgbField::from_texels(truth->width, truth->height, truth->indirect, truth->valid, truth->indirect_variance);
}

// Long because it is the method's knob table: one entry per knob, nothing to split.
std::vector<KnobSpec> prm_knobs() {
  return {
      {.name = "entries",
       .description = "entry points",
       .kind = KnobKind::Integer,
       .default_grid = {"256", "1024", "4096"},
       .min_value = 1,
       .max_value = 1'000'000},
      {.name = "clusters",
       .description = "entry-point clusters (stored panes)",
       .kind = KnobKind::Integer,
       .default_grid = {"32", "128"},
       .min_value = 1,
       .max_value = 65536},
      {.name = "active",
       .description = "clusters summed per frame (K heaviest; 0: all)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 65536},
      {.name = "density",
       .description = "pane (atlas) texels per metre",
       .kind = KnobKind::Real,
       .default_grid = {"4"},
       .min_value = 0.01,
       .max_value = 1e4},
      {.name = "pane_density",
       .description = "pane texels per metre, upsampled per chart to the atlas's `density` (0: the same)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1e4},
      {.name = "pane_threshold",
       .description = "pane blocks kept above this fraction of their cluster's peak (0: every lit block)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1},
      {.name = "pane_tile",
       .description = "pane block side in pane texels",
       .kind = KnobKind::Integer,
       .default_grid = {"8"},
       .min_value = 1,
       .max_value = 256},
      {.name = "splitting",
       .description = "paths per entry point per unit albedo (N_s)",
       .kind = KnobKind::Real,
       .default_grid = {"4"},
       .min_value = 0.01,
       .max_value = 1024},
      {.name = "pose",
       .description = "moving light pose",
       .kind = KnobKind::Choice,
       .default_grid = {"authored", "corner", "wall"},
       .choices = {"authored", "corner", "wall", "along", "wall20"}},
      {.name = "swing",
       .description = "then the light swung about Z by this many degrees (its pivot if it has a parent)",
       .kind = KnobKind::Real,
       .default_grid = {"0"},
       .min_value = -180,
       .max_value = 180},
      {.name = "world",
       .description = "what the reference path-traces: all instances, or the static ones the PRM models",
       .kind = KnobKind::Choice,
       .default_grid = {"all"},
       .choices = {"all", "static"}},
      {.name = "ref_texels",
       .description = "texels the reference path-traces and the error is scored at: a fixed random subset of the "
                      "valid texels (0: all)",
       .kind = KnobKind::Integer,
       .default_grid = {"0"},
       .min_value = 0,
       .max_value = 1e9},
      {.name = "ref_spp",
       .description = "samples per texel of the path-traced reference",
       .kind = KnobKind::Integer,
       .default_grid = {"4096"},
       .min_value = 1,
       .max_value = 1 << 20},
  };
}

ReferenceRequest prm_reference_request(const SweepScene&, const KnobSetting& k) {
  ReferenceRequest r =
      ReferenceRequest::atlas_indirect_irradiance(k.real("density"), static_cast<int>(k.integer("ref_spp")));
  r.kind = "atlas_indirect_irradiance_posed";
  r.params.emplace_back("pose", k.text("pose"));
  // Only a swung light names its swing, so unswung references keep their cache keys.
  if (k.real("swing") != 0.0) r.params.emplace_back("swing", k.text("swing"));
  if (k.text("world") != "all") r.params.emplace_back("world", k.text("world"));
  if (k.integer("ref_texels") > 0) r.params.emplace_back("texels", k.text("ref_texels"));
  return r;
}

// Coarse panes are read per chart at the atlas's texels (pane_upsample.h), after the sum:
// the upsampling is linear, so summing upsampled panes gives the same atlas.
// None when `density` is 0 (the panes are at the atlas's density).
engine::Result<std::optional<PaneUpsampler>> atlas_upsampler(const BakeInput& input, const Prm& prm, double density) {
  if (density <= 0.0) return std::optional<PaneUpsampler>();
  const auto inputs = atlas_inputs_from(input);
  auto fine = build_atlas_layout(inputs, {.texels_per_metre = static_cast<float>(density)});
  if (!fine) return fine.error();
  auto up = PaneUpsampler::build(prm.layout, prm.texels, *fine, rasterize_atlas(*fine, inputs));
  if (!up) return up.error();
  return std::optional<PaneUpsampler>(std::move(up).value());
}

// The bake settings of one run, panes at `pane_density` texels per metre.
PrmSettings prm_settings_of(const RunContext& ctx, double pane_density) {
  PrmSettings s;
  s.texels_per_metre = static_cast<float>(pane_density);
  s.entry_points = static_cast<int>(ctx.knobs.integer("entries"));
  s.clusters = static_cast<int>(ctx.knobs.integer("clusters"));
  s.splitting = static_cast<float>(ctx.knobs.real("splitting"));
  s.pane_threshold = static_cast<float>(ctx.knobs.real("pane_threshold"));
  s.pane_tile_texels = static_cast<int>(ctx.knobs.integer("pane_tile"));
  s.seed = ctx.seed;
  s.threads = ctx.threads;
  s.progress = ctx.progress;
  return s;
}

// The bake does not see the moving light (entry points and paths start on the static
// surfaces; the light only weights them at run time), so runs that differ only in the pose or
// swing share one bake: the last two bakes of the process are kept, keyed by the scene and
// the settings (the costs report the bake's own time either way). `at_subset`: gathered only
// at the reference's valid texels (bake_prm_at).
engine::Result<std::shared_ptr<const Prm>> bake_prm_shared(const RunContext& ctx, const BakeInput& input,
                                                           const PrmSettings& s, bool at_subset) {
  static std::mutex mutex;
  static std::vector<std::pair<std::string, std::shared_ptr<const Prm>>> kept;
  const std::string key = ctx.scene.content_hash + "|" + ctx.knobs.text("entries") + "|" + ctx.knobs.text("clusters") +
                          "|" + ctx.knobs.text("splitting") + "|" + ctx.knobs.text("pane_threshold") + "|" +
                          ctx.knobs.text("pane_tile") + "|" + std::to_string(s.texels_per_metre) + "|" +
                          std::to_string(s.seed) + (at_subset ? "|subset" : "");
  {
    const std::lock_guard lock(mutex);
    for (const auto& [k, prm] : kept)
      if (k == key) return prm;
  }
  auto prm = at_subset ? bake_prm_at(input, s, ctx.reference.valid) : bake_prm(input, s);
  if (!prm) return prm.error();
  auto shared = std::make_shared<const Prm>(std::move(prm).value());
  const std::lock_guard lock(mutex);
  if (kept.size() >= 2) kept.erase(kept.begin());
  kept.emplace_back(key, shared);
  return shared;
}

engine::Result<MethodOutput> run_prm(const RunContext& ctx) {
  auto scene = posed_scene(ctx.scene.asset, ctx.knobs.text("pose"), ctx.knobs.real("swing"));
  if (!scene) return scene.error();
  const double density = ctx.knobs.real("density"), pane_density = ctx.knobs.real("pane_density");
  const bool coarse = pane_density > 0.0 && pane_density != density;
  const PrmSettings s = prm_settings_of(ctx, coarse ? pane_density : density);
  const BakeInput input = bake_input_from(*scene);
  // Dense panes without a threshold, scored at a subset of texels (ref_texels): gathered at
  // those texels only, which hold what a whole bake gives them (bake_prm_at).
  const bool at_subset = !coarse && s.pane_threshold == 0.0f && ctx.knobs.integer("ref_texels") > 0;
  auto baked = bake_prm_shared(ctx, input, s, at_subset);
  if (!baked) return baked.error();
  const std::shared_ptr<const Prm> prm = std::move(baked).value();
  auto upsampler = atlas_upsampler(input, *prm, coarse ? density : 0.0);
  if (!upsampler) return upsampler.error();
  const auto to_atlas = [&](std::vector<glm::vec3> image) { return *upsampler ? (*upsampler)->apply(image) : image; };
  const int width = coarse ? ctx.reference.width : prm->width, height = coarse ? ctx.reference.height : prm->height;
  if (width != ctx.reference.width || height != ctx.reference.height)
    return engine::Error{.message = "the PRM's atlas size differs from the reference's"};
  auto caster = make_static_caster(input);
  if (!caster) return caster.error();
  // Per-frame cost of a light change on the CPU: weights, selection and the pane sum.
  const auto t0 = std::chrono::steady_clock::now();
  const auto lights = bake_lights(input, BakeLights::Moving);
  const auto picked = relight_clusters(*prm, lights, **caster, static_cast<int>(ctx.knobs.integer("active")));
  const std::vector<glm::vec3> atlas = to_atlas(sum_panes(*prm, picked));
  const double frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  MethodOutput out;
  out.field = RgbField::from_texels(width, height, atlas, ctx.reference.valid);
  // What the K heaviest clusters leave out (not timed): the same relight with every lit
  // cluster. dropped_energy = 1 - sum lum(K sum) / sum lum(all-cluster sum) over the valid
  // texels (texels have one area at one density, so this is the share of reflected power the
  // K-sum drops); rescaled_rel_rmse: the K-sum scaled by the inverse of the share kept, the
  // error a runtime that rescaled to the full energy would have (the runtime does not).
  const auto all = relight_clusters(*prm, lights, **caster, 0);
  const std::vector<glm::vec3> full = to_atlas(sum_panes(*prm, all));
  auto lum = [](const glm::vec3& c) { return luminance(double{c.x}, double{c.y}, double{c.z}); };
  double kept = 0.0, total = 0.0;
  for (std::size_t i = 0; i < atlas.size(); ++i) {
    if (!ctx.reference.is_valid(i)) continue;
    kept += lum(atlas[i]);
    total += lum(full[i]);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.extras = {{"clusters_lit", static_cast<double>(all.size())},
                {"clusters_summed", static_cast<double>(picked.size())},
                {"dropped_energy", total > 0.0 ? 1.0 - kept / total : nan},
                {"rescaled_rel_rmse", kept > 0.0 ? relative_rmse(out.field, ctx.reference, total / kept) : nan},
                {"pane_texels", static_cast<double>(prm->pane_size())},
                {"pane_blocks", static_cast<double>(prm->panes.blocks.size())},
                {"pane_blocks_dense", static_cast<double>(prm->panes.tiles.tiles() * prm->panes.cluster_count())},
                {"pane_elements_stored", static_cast<double>(prm->panes.stored_elements())}};
  out.costs.bake_seconds = prm->stats.total_seconds;
  out.costs.frame_ms = frame_ms;
  out.costs.bytes =
      static_cast<std::uint64_t>(prm->panes.stored_elements()) * 3u * 2u;  // half-float panes, kept blocks
  return out;
}

}  // namespace

void register_prm_sweep(SweepRegistry& registry) {
  // pt-3: emissive materials are dark too (pt-2 kept them, so a scene with an emissive
  // surface, such as the demo level's ceiling panel, had its light in the reference).
  // pt-4: a texel's lights from below its face are dark too (reference_sweep.cpp, pt-4).
  // pt-5: the field carries its sampling variance (the error against the noise-free truth).
  registry.add_reference_provider(
      {.kind = "atlas_indirect_irradiance_posed", .version = "pt-5", .compute = prm_reference});

  SweepMethod m;
  m.name = method_descriptor(EffectMethod::Prm).key;  // gi/methods.h
  m.description =
      "precomputed radiance maps (Szécsi 2006): entry points x clusters x active K x density x splitting, moving light "
      "at several poses";
  m.knobs = prm_knobs();
  m.reference_for = prm_reference_request;
  m.run = run_prm;
  registry.add_method(std::move(m));
}

}  // namespace gi
