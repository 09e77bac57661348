#include "sweep/sweep_runner.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "core/stopwatch.h"
#include "sweep/atlas_split_truth.h"
#include "sweep/reference_cache.h"

namespace gi {
namespace {

std::string layout_problem(const RgbField& out, const RgbField& ref) {
  if (!out.consistent()) return "the method's output vector sizes do not match its width x height";
  if (!out.same_layout(ref)) {
    return "the method's output is " + std::to_string(out.width) + "x" + std::to_string(out.height) +
           " but the reference is " + std::to_string(ref.width) + "x" + std::to_string(ref.height);
  }
  return {};
}

// The reference each run needs, each distinct one once: `requests` in first-use order and
// the index of every run's.
// With a split truth (options.split_truth_spp > 0) that is the method's split_truth_for.
void distinct_requests(const SweepMethod& method, const SweepScene& scene, std::span<const KnobSetting> settings,
                       int split_truth_spp, std::vector<ReferenceRequest>& requests,
                       std::vector<std::size_t>& request_of_run) {
  std::map<std::string, std::size_t> request_index;  // request key -> index into requests
  for (const KnobSetting& s : settings) {
    ReferenceRequest r =
        split_truth_spp > 0 ? method.split_truth_for(scene, s, split_truth_spp) : method.reference_for(scene, s);
    auto [it, inserted] = request_index.emplace(r.key(), requests.size());
    if (inserted) requests.push_back(std::move(r));
    request_of_run.push_back(it->second);
  }
}

// A run's costs, extras and errors against its reference into its row (NaN errors and a
// status when the run failed or its field does not match the reference's layout).
void score_row(const engine::Result<MethodOutput>& out, const ReferenceFetch& ref, const SweepOptions& options,
               SweepRow& row) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  row.error.rel_rmse = row.error.max_rel = row.error.psnr_db = nan;
  row.error.fit_scale = row.error.fit_rel_rmse = row.error.fit_max_rel = row.error.fit_psnr_db = nan;
  if (!out) {
    row.status = "run failed: " + out.error().to_string();
  } else {
    row.costs = out->costs;
    row.extras = out->extras;
    if (std::string p = layout_problem(out->field, ref.field); !p.empty()) {
      row.status = p;
    } else {
      row.error = compare_rgb(out->field, ref.field, options.metrics);
      if (!row.error.ok()) row.status = row.error.problem;
      // A reference that knows its own noise: the error against the truth (error_metrics.h).
      if (row.error.ok() && std::isfinite(row.error.reference_noise)) {
        row.extras.emplace_back(std::string(kReferenceNoiseExtra), row.error.reference_noise);
        if (std::isfinite(row.error.truth_rel_rmse))
          row.extras.emplace_back(std::string(kTruthErrorExtra), row.error.truth_rel_rmse);
      }
    }
  }
}

}  // namespace

// Long because its two loops (the references, then the runs) drive one progress state and one
// cancel flag through the same report callback; apart, those would be passed back and forth.
engine::Result<SweepResult> run_sweep(const SweepRegistry& registry, const SweepMethod& method, const SweepScene& scene,
                                      std::span<const KnobSetting> settings, const SweepOptions& options,
                                      const SweepProgressFn& progress, const SweepLogFn& log) {
  SweepResult result;
  const ReferenceCache cache(options.cache_dir);

  // Requests first: the number of distinct references is part of the work total.
  if (options.split_truth_spp > 0 && !method.split_truth_for)
    return engine::Error{"method " + method.name, "", "this method cannot be judged against a split truth"};
  std::vector<ReferenceRequest> requests;
  std::vector<std::size_t> request_of_run;
  distinct_requests(method, scene, settings, options.split_truth_spp, requests, request_of_run);
  for (const ReferenceRequest& r : requests) {
    if (registry.find_provider(r.kind) == nullptr) {
      return engine::Error{"method " + method.name, r.key(),
                           "no reference provider is registered for kind '" + r.kind + "'"};
    }
  }

  SweepProgress state;
  state.units_total = requests.size() + settings.size();
  bool cancelled = false;
  auto report = [&](double fraction) {
    state.current_fraction = fraction;
    if (progress && !progress(state)) cancelled = true;
    return !cancelled;
  };
  const ProgressFn unit_progress = [&](double f) { return report(f); };

  std::vector<ReferenceFetch> references;
  std::vector<RgbField> split_truths;  // with options.split_truth_spp, as references
  for (const ReferenceRequest& r : requests) {
    state.current = "reference " + r.key();
    if (!report(0.0)) break;
    engine::Result<ReferenceFetch> fetched =
        fetch_reference(cache, *registry.find_provider(r.kind), scene, r, options.threads, unit_progress);
    if (cancelled) break;
    if (!fetched) return fetched.error();
    if (!fetched->warning.empty() && log) log(fetched->warning);
    (fetched->from_cache ? result.references_from_cache : result.references_computed) += 1;
    if (options.split_truth_spp > 0) {  // the runs' reference is its indirect half
      split_truths.push_back(std::move(fetched->field));
      fetched->field = unstack_split_truth(split_truths.back()).indirect;
    }
    references.push_back(std::move(fetched.value()));
    ++state.units_done;
  }

  for (std::size_t run = 0; run < settings.size() && !cancelled; ++run) {
    const ReferenceFetch& ref = references[request_of_run[run]];
    SweepRow row;
    row.method = method.name;
    row.scene = scene.display_name();
    row.knobs = settings[run];
    row.reference_key = ref.key;
    state.current = "run " + (row.knobs.label().empty() ? std::string("(no knobs)") : row.knobs.label());
    if (!report(0.0)) break;
    const auto start = std::chrono::steady_clock::now();
    const RgbField* split_truth = split_truths.empty() ? nullptr : &split_truths[request_of_run[run]];
    engine::Result<MethodOutput> out =
        method.run(RunContext{scene, row.knobs, requests[request_of_run[run]], ref.field, options.seed, options.threads,
                              unit_progress, split_truth});
    row.wall_seconds = seconds_since(start);
    if (cancelled) break;  // a cancelled run's output is not a measurement
    score_row(out, ref, options, row);
    result.rows.push_back(std::move(row));
    ++state.units_done;
    state.current_fraction = 0.0;
  }
  result.cancelled = cancelled;
  if (!cancelled && progress) {
    state.current.clear();
    progress(state);
  }
  return result;
}

}  // namespace gi
