#pragma once
// The measuring harness (target gi::sweep): a GI method's accuracy against the reference
// path tracer and its cost, over a grid of its quality knobs, written as CSV, a Markdown
// summary with the Pareto front and the presets it implies (docs/sweeps/README.md). The
// gi-sweep tool is its command line.
//   auto report = gi::run_sweep({.method = "light_atlas", .scene = "assets/cornell_box.gltf",
//                                .knobs = {"vpls=100,300"}, .out_dir = "docs/sweeps"});
//   if (report) std::printf("%s\n", report->csv.c_str());

#include <engine/result.h>
#include <gi/log.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace engine {
struct SceneAsset;
}

namespace gi {

/// One knob of a sweep method, as `--list` shows it.
struct SweepKnobInfo {
  std::string name;
  std::string description;
  std::string kind;          ///< "integer", "real" or "choice".
  std::string range;         ///< "[1, 1e+06]" or "{a, b}".
  std::string default_grid;  ///< "100,300,1000".
};

struct SweepMethodInfo {
  std::string name;
  std::string description;
  std::vector<SweepKnobInfo> knobs;
};

/// The shipped sweep methods (the reference path tracer and every GI method).
std::vector<SweepMethodInfo> sweep_methods();
/// The registered reference providers, "kind@version".
std::vector<std::string> sweep_reference_providers();

/// One sweep: a method on a scene over a knob grid.
struct SweepRequest {
  std::string method;               ///< A name from sweep_methods().
  std::filesystem::path scene;      ///< glTF/GLB file.
  std::vector<std::string> knobs;   ///< Overrides "name=v1,v2,..." of the default grid.
  std::filesystem::path out_dir;    ///< Receives <method>_<scene>.csv and .md (created when missing).
  std::filesystem::path cache_dir;  ///< Reference cache; empty: out_dir/reference-cache.
  unsigned threads = 0;             ///< For methods and references; 0: all hardware threads.
  std::uint64_t seed = 1;
  bool frame_cost = false;                       ///< Pareto front over per-frame ms instead of bake seconds.
  double preset_targets[3] = {0.2, 0.05, 0.01};  ///< Relative RMSE of preview, medium, high.
  double exposure = 1.0;                         ///< Before tonemapping, for PSNR.
  /// Applied to the scene once loaded, before the method and its references see it (gi-sweep's
  /// --sky and --sun, parsed as gi-bake parses them). The scene's fingerprint, and so every
  /// reference cache key, covers what it changes. Empty: the scene as loaded.
  std::function<void(engine::SceneAsset&)> edit_scene;
  /// The command-line arguments that make edit_scene ("--sky '...' --sun '...'"), for the
  /// command written at the top of the Markdown summary.
  std::string edit_scene_args;
  /// The scene without its textures (gi::without_textures, as gi-bake --untextured), after
  /// edit_scene; in the fingerprint too.
  bool untextured = false;
  /// > 0: judge the runs against the method's split truth (indirect and total irradiance of
  /// the light atlas's texels, two path-traced estimates of this many samples per texel);
  /// the runs then also report the indirect-dominated and whole-lightmap errors. 0: the
  /// method's usual reference.
  int split_truth_spp = 0;
};

/// Where a sweep is: runs (and references) done of the total, the current one and how far it is.
struct SweepStatus {
  std::size_t units_done = 0;
  std::size_t units_total = 0;
  std::string current;  ///< "reference <key>" or "run <knobs>".
  double current_fraction = 0.0;
  double fraction() const;  ///< Of the whole sweep, in [0, 1].
};

struct SweepHost {
  std::function<bool(const SweepStatus&)> progress;  ///< False cancels; the runs done are still written.
  LogCallback log;                                   ///< Warnings of the harness and the methods.
};

struct SweepReport {
  std::filesystem::path csv;
  std::filesystem::path markdown;
  std::size_t runs = 0;
  std::vector<std::string> failures;  ///< "<knobs>: <why>" for each run without valid metrics.
  std::size_t references_computed = 0;
  std::size_t references_from_cache = 0;
  bool cancelled = false;  ///< Stopped by the progress callback; the files hold the runs done.
};

/// Runs the sweep and writes its files. Errors: an unknown method or knob, a bad grid or
/// target (ErrorKind::Invalid), a scene that does not load, files that cannot be written.
engine::Result<SweepReport> run_sweep(const SweepRequest& request, const SweepHost& host = {});

}  // namespace gi
