#pragma once
// What a GI method and a reference provider give the sweep harness: knobs, the reference a
// run needs, and a run function returning linear output plus costs.
//   gi::SweepMethod m{.name = "light_atlas", .knobs = {texel_density}, .reference_for = ..., .run = bake_and_sample};
//   registry.add_method(std::move(m));

#include <engine/result.h>
#include <gi/rgb_field.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "sweep/knob_setting.h"
#include "sweep/knob_spec.h"
#include "sweep/reference_request.h"
#include "sweep/sweep_scene.h"

namespace gi {

/// Fraction done in [0, 1]; return false to cancel (the work then returns an Error soon).
/// The same signature as gi::ProgressCallback, so it can be handed to bakers directly.
using ProgressFn = std::function<bool(double fraction_done)>;

/// What one run cost.
struct RunCosts {
  double bake_seconds = 0.0;                                   ///< Precomputation wall time.
  double frame_ms = std::numeric_limits<double>::quiet_NaN();  ///< Per-frame runtime cost; NaN: not applicable.
  std::uint64_t bytes = 0;                                     ///< Size of the baked data / runtime memory.
};

/// A run's output: same width, height and element order as the reference, linear values in
/// the reference's unit, invalid elements masked out.
struct MethodOutput {
  RgbField field;
  RunCosts costs;
  /// Method-specific measurements of this run (name, value), written as `extra:<name>`
  /// columns of the CSV and the Markdown table; names as knob names. Empty for most methods.
  std::vector<std::pair<std::string, double>> extras;
};

/// Everything a run may read. References stay valid for the duration of the call.
struct RunContext {
  const SweepScene& scene;
  const KnobSetting& knobs;         ///< Canonical values of every declared knob.
  const ReferenceRequest& request;  ///< What reference_for() asked for.
  const RgbField& reference;        ///< The reference data (for its layout and mask; not to cheat).
  std::uint64_t seed = 1;
  unsigned threads = 0;        ///< 0: all hardware threads.
  const ProgressFn& progress;  ///< Call it; stop and return an Error when it returns false.
  /// With SweepOptions::split_truth_spp: the stacked split truth (atlas_split_truth.h) whose
  /// indirect half is `reference`; the run scores its whole lightmap against it into its
  /// extras (split_truth_extras). Null otherwise.
  const RgbField* split_truth = nullptr;
};

/// A GI method as the sweep harness sees it.
struct SweepMethod {
  std::string name;         ///< Command-line name ([a-z0-9_-]+).
  std::string description;  ///< One line.
  std::vector<KnobSpec> knobs;
  /// The reference a run with these knobs is compared against.
  std::function<ReferenceRequest(const SweepScene&, const KnobSetting&)> reference_for;
  /// Optional, for methods that bake a light atlas: the split truth (indirect and total, two
  /// path-traced estimates of `spp` samples per texel with different seeds) a run with these
  /// knobs is judged against when SweepOptions::split_truth_spp = spp > 0. It replaces
  /// reference_for's reference: the runs' main error is against its indirect half.
  std::function<ReferenceRequest(const SweepScene&, const KnobSetting&, int spp)> split_truth_for;
  /// Renders or bakes with the knobs. Errors fail this run only (reported in its row).
  std::function<engine::Result<MethodOutput>(const RunContext&)> run;
};

/// Everything a reference computation may read.
struct ReferenceJob {
  const SweepScene& scene;
  const ReferenceRequest& request;
  unsigned threads = 0;  ///< The result must not depend on it (it is not part of the cache key).
  const ProgressFn& progress;
};

/// Computes references of one kind (the path tracer registers "camera_image" and
/// "atlas_indirect_irradiance"). Results are cached on disk by scene content, kind,
/// version and request key, so a provider must be deterministic for those.
struct ReferenceProvider {
  std::string kind;     ///< The ReferenceRequest::kind it serves.
  std::string version;  ///< Bump when its output changes (a fix, a new default): old caches are then ignored.
  std::function<engine::Result<RgbField>(const ReferenceJob&)> compute;
};

}  // namespace gi
