#pragma once
// Runs one method over a grid of knob settings on one scene: fetches (or computes and
// caches) each distinct reference once, runs the method per setting, measures the error.
//   auto result = gi::run_sweep(registry, *method, scene, grid.settings(), {.cache_dir = "cache"});
//   gi::write_file_atomically("out/sweep.csv", gi::sweep_csv(result->rows));

#include <engine/result.h>
#include <gi/error_metrics.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sweep/sweep_registry.h"

namespace gi {

/// Extras the harness adds to a row when the reference carries its sampling variance
/// (RgbField::variance): the reference's own relative noise and the error against the truth.
inline constexpr std::string_view kReferenceNoiseExtra = "ref_noise";
inline constexpr std::string_view kTruthErrorExtra = "truth_rel_rmse";

struct SweepOptions {
  std::filesystem::path cache_dir;  ///< Reference cache; empty: references are not cached on disk.
  unsigned threads = 0;             ///< Passed to methods and providers; 0: all hardware threads.
  std::uint64_t seed = 1;           ///< Passed to methods.
  /// > 0: judge the runs against SweepMethod::split_truth_for's truth at this many samples
  /// per texel (each of its two estimates); the method must have one. 0: reference_for's.
  int split_truth_spp = 0;
  MetricOptions metrics;
};

/// One run: what was run, how accurate it was and what it cost.
struct SweepRow {
  std::string method;
  std::string scene;
  KnobSetting knobs;
  ErrorReport error;  ///< Against the reference (NaN metrics when the run failed).
  RunCosts costs;     ///< As the method reported them.
  std::vector<std::pair<std::string, double>>
      extras;                 ///< MethodOutput::extras, as the method reported them (+ the harness's, above).
  double wall_seconds = 0.0;  ///< Wall time of the run call, measured by the harness.
  std::string reference_key;  ///< The full reference cache key.
  std::string status = "ok";  ///< "ok", or why the run has no valid metrics.

  bool ok() const { return status == "ok"; }
};

/// Where the sweep is: work units are the distinct references, then the runs.
struct SweepProgress {
  std::size_t units_done = 0;
  std::size_t units_total = 0;
  std::string current;  ///< "reference <key>" or "run <knob label>".
  double current_fraction = 0.0;
};
/// Return false to cancel the sweep.
using SweepProgressFn = std::function<bool(const SweepProgress&)>;
/// Receives warnings (discarded cache files, cache write failures) as lines.
using SweepLogFn = std::function<void(const std::string&)>;

struct SweepResult {
  std::vector<SweepRow> rows;  ///< One per completed run, in grid order.
  bool cancelled = false;      ///< The progress callback asked to stop; rows holds the runs done.
  std::size_t references_computed = 0;
  std::size_t references_from_cache = 0;
};

/// Runs the sweep. A failed or invalid run becomes a row whose status says why (for example
/// an output of the wrong size, NaN values, a method Error); the sweep goes on. Errors: no
/// provider for a requested reference kind, or a reference that cannot be computed.
engine::Result<SweepResult> run_sweep(const SweepRegistry& registry, const SweepMethod& method, const SweepScene& scene,
                                      std::span<const KnobSetting> settings, const SweepOptions& options,
                                      const SweepProgressFn& progress = {}, const SweepLogFn& log = {});

}  // namespace gi
