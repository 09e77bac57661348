// The public face of the harness (gi/sweep.h): the shipped registry, a request run end to
// end, its files written.
#include <gi/frame_truth.h>
#include <gi/sweep.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "io/atomic_file.h"
#include "sweep/builtin_methods.h"
#include "sweep/knob_grid.h"
#include "sweep/knob_spec.h"
#include "sweep/sweep_csv.h"
#include "sweep/sweep_runner.h"
#include "sweep/sweep_scene.h"
#include "sweep/sweep_summary.h"

namespace gi {

namespace {

const SweepRegistry& shipped_registry() {
  static const SweepRegistry registry = [] {
    SweepRegistry r;
    register_builtin_sweep_methods(r);
    return r;
  }();
  return registry;
}

const char* kind_name(KnobKind k) {
  switch (k) {
    case KnobKind::Integer:
      return "integer";
    case KnobKind::Real:
      return "real";
    case KnobKind::Choice:
      return "choice";
  }
  return "?";
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

std::string file_stem_safe(std::string s) {
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) c = '_';
  return s;
}

// The gi-sweep command line that makes `r` (paths as given, so relative to where it ran).
std::string sweep_command(const SweepRequest& r) {
  auto arg = [](const std::string& s) { return s.find_first_of(" \t'\"$\\") == std::string::npos ? s : "'" + s + "'"; };
  std::string c = "gi-sweep --method " + arg(r.method) + " --scene " + arg(r.scene.generic_string());
  for (const std::string& k : r.knobs) c += " --knob " + arg(k);
  c += " --out " + arg(r.out_dir.generic_string());
  if (!r.cache_dir.empty()) c += " --cache " + arg(r.cache_dir.generic_string());
  c += " --threads " + std::to_string(r.threads);
  if (r.seed != 1) c += " --seed " + std::to_string(r.seed);
  if (r.frame_cost) c += " --cost frame";
  const SweepRequest defaults;
  if (!std::equal(std::begin(r.preset_targets), std::end(r.preset_targets), std::begin(defaults.preset_targets)))
    c += " --presets " + format_number(r.preset_targets[0]) + "," + format_number(r.preset_targets[1]) + "," +
         format_number(r.preset_targets[2]);
  if (r.exposure != defaults.exposure) c += " --exposure " + format_number(r.exposure);
  if (!r.edit_scene_args.empty()) c += " " + r.edit_scene_args;
  if (r.untextured) c += " --untextured";
  if (r.split_truth_spp > 0) c += " --split-truth " + std::to_string(r.split_truth_spp);
  return c;
}

engine::Error invalid(const engine::Error& e) {
  engine::Error out = e;
  out.kind = engine::ErrorKind::Invalid;
  return out;
}

// The request's scene with its edits (lighting, textures) applied and fingerprinted.
engine::Result<SweepScene> load_edited_scene(const SweepRequest& request) {
  auto scene = load_sweep_scene(request.scene);
  if (!scene || (!request.edit_scene && !request.untextured)) return scene;
  if (request.edit_scene) request.edit_scene(scene->asset);
  if (request.untextured) scene->asset = without_textures(std::move(scene->asset));
  auto hash = scene_fingerprint(scene->path, scene->asset);
  if (!hash) return hash.error();
  scene->content_hash = hash.value();
  return scene;
}

}  // namespace

double SweepStatus::fraction() const {
  const double total = static_cast<double>(std::max<std::size_t>(units_total, 1));
  const double f = (static_cast<double>(units_done) + std::clamp(current_fraction, 0.0, 1.0)) / total;
  return std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 0.0;
}

std::vector<SweepMethodInfo> sweep_methods() {
  std::vector<SweepMethodInfo> out;
  for (const SweepMethod& m : shipped_registry().methods()) {
    SweepMethodInfo info{m.name, m.description, {}};
    for (const KnobSpec& k : m.knobs)
      info.knobs.push_back({k.name, k.description, kind_name(k.kind),
                            k.kind == KnobKind::Choice
                                ? "{" + join(k.choices, ", ") + "}"
                                : "[" + format_number(k.min_value) + ", " + format_number(k.max_value) + "]",
                            join(k.default_grid, ",")});
    out.push_back(std::move(info));
  }
  return out;
}

std::vector<std::string> sweep_reference_providers() {
  std::vector<std::string> out;
  for (const ReferenceProvider& p : shipped_registry().providers()) out.push_back(p.kind + "@" + p.version);
  return out;
}

engine::Result<SweepReport> run_sweep(const SweepRequest& request, const SweepHost& host) {
  const SweepRegistry& registry = shipped_registry();
  const SweepMethod* method = registry.find_method(request.method);
  if (method == nullptr) {
    std::vector<std::string> names;
    for (const SweepMethod& m : registry.methods()) names.push_back(m.name);
    return engine::invalid_request("unknown sweep method '" + request.method + "' (registered: " + join(names, ", ") +
                                   ")");
  }
  auto grid = make_knob_grid(*method, request.knobs);
  if (!grid) return invalid(grid.error());
  const PresetTargets targets{request.preset_targets[0], request.preset_targets[1], request.preset_targets[2]};
  for (double t : request.preset_targets)
    if (!(t > 0.0) || !std::isfinite(t)) return engine::invalid_request("preset targets must be finite and > 0");
  auto scene = load_edited_scene(request);
  if (!scene) return scene.error();
  if (request.split_truth_spp < 0) return engine::invalid_request("the split truth's samples must be >= 0");
  std::error_code ec;
  std::filesystem::create_directories(request.out_dir, ec);
  if (ec) return engine::Error{request.out_dir.string(), "", "cannot create the output folder: " + ec.message()};

  const std::vector<KnobSetting> settings = grid->settings();
  if (host.log)
    host.log(LogLevel::Info, method->name + " on " + scene->display_name() + " (" + scene->content_hash +
                                 "): " + std::to_string(settings.size()) + " run(s)");
  SweepOptions options;
  options.cache_dir = request.cache_dir.empty() ? request.out_dir / "reference-cache" : request.cache_dir;
  options.threads = request.threads;
  options.seed = request.seed;
  options.split_truth_spp = request.split_truth_spp;
  options.metrics.exposure = request.exposure;
  auto result = run_sweep(
      registry, *method, *scene, settings, options,
      [&](const SweepProgress& p) {
        return !host.progress || host.progress({p.units_done, p.units_total, p.current, p.current_fraction});
      },
      [&](const std::string& warning) {
        if (host.log) host.log(LogLevel::Warning, warning);
      });
  if (!result) return result.error();

  const std::filesystem::path stem = request.out_dir / file_stem_safe(method->name + "_" + scene->path.stem().string());
  SweepReport report;
  report.csv = std::filesystem::path(stem).concat(".csv");
  report.markdown = std::filesystem::path(stem).concat(".md");
  const SweepSummary summary =
      summarize_sweep(result->rows, {.cost = request.frame_cost ? SweepCost::FrameMs : SweepCost::BakeSeconds,
                                     .targets = targets,
                                     .command = sweep_command(request)});
  if (engine::Status s = write_file_atomically(report.csv, sweep_csv(result->rows)); !s) return s.error();
  if (engine::Status s = write_file_atomically(report.markdown, sweep_summary_markdown(result->rows, summary)); !s)
    return s.error();
  report.runs = result->rows.size();
  for (const SweepRow& r : result->rows)
    if (!r.ok()) report.failures.push_back(r.knobs.label() + ": " + r.status);
  report.references_computed = result->references_computed;
  report.references_from_cache = result->references_from_cache;
  report.cancelled = result->cancelled;
  return report;
}

}  // namespace gi
