// gi::bake_bundle: plan, bake each method into a staged copy of the bundle, swap it in
// (gi/bake.h). The options' mapping onto each method's settings is bake_options.h, the
// staged directory io/staged_directory.h, bake_stats.json bake_stats.h, distributed bakes
// bake_sharding.h.
#include <gi/bake.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include "antiradiance/antiradiance_io.h"
#include "antiradiance/antiradiance_region.h"
#include "bake/bake_options.h"
#include "bake/bake_sharding.h"
#include "bake/bake_stage.h"
#include "bake/bake_stats.h"
#include "brf/brf_bake.h"
#include "brf/brf_io.h"
#include "brf/brf_mesh.h"
#include "bundle/bundle_reader.h"
#include "bundle/geometry_hash.h"
#include "bundle/manifest.h"
#include "core/stopwatch.h"
#include "dlm/dlm.h"
#include "dlm/dlm_io.h"
#include "io/staged_directory.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "plan/plan_json.h"
#include "prm/prm.h"
#include "prm/prm_io.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// What a method's bake cost, for bake_stats.json (stage name -> seconds).
using Timings = nlohmann::json;

engine::Status bake_atlas(const BakeInput& input, const fs::path& dir, const BakeOptions& o, const BakeStage& stage,
                          Timings& timings, const MergedParts* merged = nullptr) {
  auto settings = atlas_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(format_line("light atlas of %s, preset %s: %d VPLs x %d samples, %d bounces, %g texels/m",
                        scene_file_name(input).c_str(), o.preset.c_str(), settings->vpl_count,
                        settings->samples_per_vpl, settings->bounces, double{settings->texels_per_metre}));
  auto bake = merged ? merge_light_atlas(input, *settings, merged->atlas) : bake_light_atlas(input, *settings);
  if (!bake) return bake.error();
  const LightAtlasStats& st = bake->stats;
  stage.log(format_line(
      "  atlas %dx%d at %g texels/m, %zu texels lit; %zu VPLs, %zu sample points, %zu light points, %zu shots",
      bake->width, bake->height, double{bake->layout.texels_per_metre}, st.valid_texels, st.vpls, st.sample_points,
      st.light_points, st.shots));
  stage.log(format_line(
      "  time: VPLs %.2f s, direct %.2f s, propagation %.2f s, final shooting %.2f s; total %.2f s; %.1f M rays",
      st.vpl_seconds, st.direct_seconds, st.propagate_seconds, st.final_seconds, st.total_seconds,
      static_cast<double>(st.rays) * 1e-6));
  timings = {{"vpl_seconds", st.vpl_seconds},
             {"direct_seconds", st.direct_seconds},
             {"propagate_seconds", st.propagate_seconds},
             {"final_seconds", st.final_seconds},
             {"total_seconds", st.total_seconds}};
  return save_light_atlas(dir, *bake, input);
}

engine::Status bake_prm_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o,
                               const BakeStage& stage, Timings& timings, const MergedParts* merged = nullptr) {
  auto settings = prm_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(format_line("PRM of %s, preset %s: %d entry points, %d clusters, splitting %g, %g texels/m",
                        scene_file_name(input).c_str(), o.preset.c_str(), settings->entry_points, settings->clusters,
                        double{settings->splitting}, double{settings->texels_per_metre}));
  auto prm = merged ? merge_prm(input, *settings, merged->prm) : bake_prm(input, *settings);
  if (!prm) return prm.error();
  const PrmStats& st = prm->stats;
  stage.log(
      format_line("  panes %dx%d, %zu texels each, %d clusters (%.1f MB as half floats); %zu paths, %zu virtual lights",
                  prm->width, prm->height, prm->pane_size(), prm->cluster_count,
                  static_cast<double>(prm->pane_size()) * prm->cluster_count * 6.0 / 1e6, st.paths, st.path_nodes));
  stage.log(format_line("  time: walks %.2f s, panes %.2f s; total %.2f s; %.1f M rays", st.walk_seconds,
                        st.pane_seconds, st.total_seconds, static_cast<double>(st.rays) * 1e-6));
  timings = {{"walk_seconds", st.walk_seconds}, {"pane_seconds", st.pane_seconds}, {"total_seconds", st.total_seconds}};
  return save_prm(dir, *prm, input);
}

// The atlas the runtime composites antiradiance into (GISystem: the light atlas's layout,
// else the PRM's) as the bundle in `dir` holds it; none when it holds neither.
std::optional<AtlasLayout> runtime_atlas_layout(const fs::path& dir, const BakeInput& input) {
  for (const char* method : {kLightAtlasMethod, kPrmMethod}) {
    auto bundle = BundleReader::open(dir, method, input, "re-bake");
    if (!bundle) continue;
    JsonFields f = bundle->fields();
    const BakedAtlasLayout baked = read_baked_atlas_layout(f);
    if (f.error()) continue;
    auto layout = bundle->atlas_layout(input, baked, "atlas layout");
    if (layout) return std::move(layout).value();
  }
  return std::nullopt;
}

engine::Status bake_antiradiance_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o,
                                        const BakeStage& stage, Timings& timings, const MergedParts* parts = nullptr) {
  const AntiradianceSettings s = antiradiance_settings(o);
  const auto start = Clock::now();
  // A merge (docs/distributed-bake.md): the links from the shards, the rest baked here.
  auto bake = parts != nullptr && !parts->antiradiance.empty()
                  ? bake_antiradiance_from_link_shards(input, s, parts->antiradiance)
                  : bake_antiradiance(input, s);
  if (!bake) return bake.error();
  stage.log(format_line("antiradiance of %s, preset %s: %zu elements (%zu leaves), %d bins, %zu static links, %.2f s",
                        scene_file_name(input).c_str(), o.preset.c_str(), bake->hierarchy.nodes.size(),
                        bake->hierarchy.leaf_count(), s.bins_per_side * s.bins_per_side,
                        bake->static_links.links.size(), seconds_since(start)));
  // links_seconds: linking (a merge: putting the shards' links in place).
  timings["links_seconds"] = bake->seconds.links;
  timings["static_links_seconds"] = bake->seconds.static_links;
  timings["direct_seconds"] = bake->seconds.direct;
  timings["solve_seconds"] = bake->seconds.solve;
  // What a load at the baked pose computes (the posed links, the texel blends of the atlas
  // baked before it in this bundle), stored so the load reads it.
  const auto at_pose_start = Clock::now();
  const std::optional<AtlasLayout> layout = runtime_atlas_layout(dir, input);
  prepare_antiradiance_load(*bake, input, layout ? &*layout : nullptr);
  timings["at_pose_seconds"] = seconds_since(at_pose_start);
  const auto save_start = Clock::now();
  auto saved = save_antiradiance(dir, *bake, input);
  timings["save_seconds"] = seconds_since(save_start);
  return saved;
}

engine::Status bake_brf_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o, const BakeHost& host,
                               Timings& timings) {
  auto settings = brf_settings(o);
  if (!settings) return settings.error();
  auto sources = dynamic_brf_meshes(input);
  if (!sources) return sources.error();
  const BakeStage header{host, "BRF"};
  const PcaBasisSettings& b = settings->basis;
  const RadianceFieldSettings& f = settings->field;
  header.log(
      format_line("basis radiance fields of %s, preset %s: %zu dynamic meshes; %d lights, N = %d, %d spheres x 6x%dx%d "
                  "points, %d SH bands, %d directions",
                  scene_file_name(input).c_str(), o.preset.c_str(), sources->size(), b.lights, b.basis, f.spheres,
                  f.face_resolution, f.face_resolution, f.sh_bands, f.directions));
  if (sources->empty()) {
    header.log("  no dynamic mesh: nothing to bake");
    return {};
  }
  BrfBake bake{.settings = *settings, .meshes = {}};
  for (const BrfSource& s : *sources) {
    const BakeStage stage{host, "BRF " + s.name};
    auto mesh = bake_brf_mesh(s, *settings, stage.progress());
    if (!mesh) return mesh.error();
    stage.log(
        format_line("  %-16s %6zu vertices, %zu instances, basis %d of %d kept, condition %.3g, field %.2f MB, %.2f s",
                    s.name.c_str(), s.mesh.positions.size(), s.instances.size(), mesh->model.basis.basis_count, b.basis,
                    mesh->model.basis.condition, static_cast<double>(mesh->model.field.bytes()) / 1e6,
                    mesh->basis_seconds + mesh->field_seconds));
    if (mesh->model.glossy)
      stage.log(format_line("  %-16s glossy (GGX alpha %.3f, f0 %.2f): %d BRDF terms, weighted BRDF error %.2f", "",
                            static_cast<double>(mesh->model.glossy->lobe.alpha),
                            static_cast<double>(mesh->model.glossy->lobe.f0), mesh->model.glossy->terms,
                            static_cast<double>(mesh->model.glossy->relative_error)));
    timings[s.name] = {{"basis_seconds", mesh->basis_seconds}, {"field_seconds", mesh->field_seconds}};
    bake.meshes.push_back(std::move(mesh).value());
  }
  return save_brf(dir, bake, input);
}

engine::Status bake_dlm_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o,
                               const BakeStage& stage, Timings& timings) {
  auto settings = dlm_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(
      format_line("directional light maps of %s, preset %s: %d directions, %llu photons, splat radius %g texels, "
                  "%g texels/m, roughness < %g",
                  scene_file_name(input).c_str(), o.preset.c_str(), settings->directions,
                  static_cast<unsigned long long>(settings->photons), double{settings->splat_radius_texels},
                  double{settings->texels_per_metre}, double{settings->glossy_roughness}));
  auto dlm = bake_dlm(input, *settings);
  if (!dlm) return dlm.error();
  const DlmStats& st = dlm->stats;
  stage.log(format_line(
      "  %zu glossy texels, %zu stored (%.2f MB as halves, %zu B per texel); %llu deposits, %.1f M rays",
      st.glossy_texels, dlm->texel_count(), static_cast<double>(dlm->radiance.size()) * 2.0 / 1e6,
      dlm->directions.size() * 6, static_cast<unsigned long long>(st.deposits), static_cast<double>(st.rays) * 1e-6));
  stage.log(format_line("  time: photons %.2f s; total %.2f s", st.trace_seconds, st.total_seconds));
  timings = {{"trace_seconds", st.trace_seconds}, {"total_seconds", st.total_seconds}};
  return save_dlm(dir, *dlm, input);
}

// A method's one key (gi/methods.h): gi-bake --methods, the plan, the manifest.
std::string key_of(EffectMethod m) { return std::string(method_descriptor(m).key); }

// The methods a bake bakes, in order: options.methods, or what the plan calls for and this
// build can bake (the rest in report.skipped); a sky-lit PRM brings the atlas with it.
engine::Result<std::vector<std::string>> methods_to_bake(const BakeInput& input, const BakeOptions& options,
                                                         const BakeHost& host, BakeReport& report) {
  const std::vector<std::string> bakeable = bakeable_methods();
  std::vector<std::string> methods = options.methods;
  if (methods.empty()) {
    for (const PlannedEffect& e : report.plan.effects) {
      if (!e.enabled) continue;
      const std::string key(effect_key(e.method));
      if (std::find(bakeable.begin(), bakeable.end(), key) != bakeable.end() && e.available)
        methods.push_back(key);
      else
        report.skipped.push_back(key);
    }
    for (const std::string& key : report.skipped)
      if (host.log)
        host.log(LogLevel::Warning, "skipping " + key + ": the scene calls for it but this build cannot bake it");
  }
  for (const std::string& key : methods)
    if (std::find(bakeable.begin(), bakeable.end(), key) == bakeable.end())
      return engine::invalid_request("method '" + key + "' is not available in this build (available: " + [&] {
        std::string list;
        for (const std::string& b : bakeable) list += (list.empty() ? "" : ", ") + b;
        return list;
      }() + ")");

  // The sky in a PRM bake (docs/prm.md "The sky"): the sky is a static source, so its light
  // lives in the light atlas the PRM provider composes with (the atlas's final gather
  // resolves it per texel, the PRM's entry points only per cluster and compete for the K
  // active panes). A PRM asked for alone on a sky-lit scene bakes that atlas too, first.
  if (engine::sky_lit(input.environment.sky_radiance, input.environment.sky_gradient) &&
      std::find(methods.begin(), methods.end(), key_of(EffectMethod::Prm)) != methods.end() &&
      std::find(methods.begin(), methods.end(), key_of(EffectMethod::LightAtlas)) == methods.end()) {
    methods.insert(methods.begin(), key_of(EffectMethod::LightAtlas));
    if (host.log)
      host.log(LogLevel::Info, "baking the light atlas too: it carries the sky the PRM composes with (docs/prm.md)");
  }
  return methods;
}

}  // namespace

std::vector<std::string> bakeable_methods() {
  // Every method, in the order a bake runs them (the PRM and antiradiance after the light atlas).
  return {key_of(EffectMethod::LightAtlas), key_of(EffectMethod::Prm), key_of(EffectMethod::DirectionalLightMaps),
          key_of(EffectMethod::BasisRadianceFields), key_of(EffectMethod::Antiradiance)};
}

engine::Result<BakeReport> bake_bundle(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                       const BakeHost& host) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  BakeReport report;
  report.plan = plan(input, {.preset = options.preset,
                             .moving_lights = options.moving_lights,
                             .texels_per_metre = options.texels_per_metre,
                             .vpls = options.vpls,
                             .samples_per_vpl = options.samples_per_vpl,
                             .bounces = options.bounces});
  // The preset is checked before anything is baked or written.
  if (auto density = light_atlas_preset(options.preset); !density) return density.error();

  auto resolved = methods_to_bake(input, options, host, report);
  if (!resolved) return resolved.error();
  const std::vector<std::string> methods = std::move(resolved).value();

  // Distributed bakes (docs/distributed-bake.md): one shard's work into its shard file, or
  // the merge of every shard's, which then bakes through the same staging + swap below.
  if (options.shard_count > 0 && !options.merge_shards)
    return bake_shard(input, bundle_dir, options, host, methods, std::move(report));
  std::optional<MergedParts> merged;
  if (options.merge_shards) {
    auto parts = read_shards(input, bundle_dir, options, methods, host);
    if (!parts) return parts.error();
    merged = std::move(parts).value();
  }

  if (methods.empty()) return report;
  auto staged = StagedDirectory::begin(bundle_dir, "bake of this bundle");
  if (!staged) return staged.error();
  const fs::path& dir = staged->path();
  nlohmann::json method_stats = nlohmann::json::object();
  for (const std::string& key : methods) {
    const auto start = Clock::now();
    Timings timings = nlohmann::json::object();
    const MergedParts* parts = merged ? &*merged : nullptr;
    const EffectMethod m = *method_from_key(key);  // methods_to_bake checked every key
    const std::string name(effect_name(m));
    engine::Status done =
        m == EffectMethod::LightAtlas             ? bake_atlas(input, dir, options, {host, name}, timings, parts)
        : m == EffectMethod::Prm                  ? bake_prm_method(input, dir, options, {host, name}, timings, parts)
        : m == EffectMethod::DirectionalLightMaps ? bake_dlm_method(input, dir, options, {host, name}, timings)
        : m == EffectMethod::Antiradiance ? bake_antiradiance_method(input, dir, options, {host, name}, timings, parts)
                                          : bake_brf_method(input, dir, options, host, timings);
    if (!done) return done.error();
    report.baked.push_back({key, seconds_since(start), method_bytes(dir, key)});
    method_stats[key] = {{"seconds", report.baked.back().seconds}, {"stages", timings}};
  }
  if (auto ok = update_manifest_plan(dir, scene_geometry_hash(input), scene_file_name(input),
                                     plan_to_json_value(report.plan));
      !ok)
    return ok.error();
  if (auto ok = update_bake_stats(dir, method_stats, options.threads); !ok) return ok.error();
  if (auto ok = staged->commit(); !ok) return ok.error();
  return report;
}

}  // namespace gi
