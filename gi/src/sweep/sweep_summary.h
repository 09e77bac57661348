#pragma once
// The Markdown summary of a sweep: every run in a table, the Pareto front of (relative
// RMSE, cost) and the suggested presets with the rule that chose them.
//   gi::SweepSummary s = gi::summarize_sweep(result.rows, {});
//   gi::write_file_atomically(dir / "atlas_cornell_box.md", gi::sweep_summary_markdown(result.rows, s));

#include <span>
#include <string>
#include <vector>

#include "sweep/pareto_front.h"
#include "sweep/sweep_runner.h"

namespace gi {

/// Which cost the trade-off is measured against.
enum class SweepCost { BakeSeconds, FrameMs };

struct SweepSummaryOptions {
  SweepCost cost = SweepCost::BakeSeconds;
  PresetTargets targets;
  std::string command;  ///< The gi-sweep command that regenerates the files (Markdown states it); empty: none.
};

struct SweepSummary {
  SweepSummaryOptions options;
  std::vector<ParetoPoint> points;    ///< One per row: (rel_rmse, cost); NaN for failed runs.
  std::vector<std::size_t> front;     ///< Row indices on the Pareto front, by cost.
  std::vector<PresetChoice> presets;  ///< Indices are row indices.
};

/// The cost of a row on the chosen axis (NaN when not applicable or the run failed).
double sweep_cost(const SweepRow& row, SweepCost cost);
/// The error of a row on the front's axis: the error against the truth when the harness
/// could estimate it (kTruthErrorExtra), else rel RMSE against the reference; NaN if failed.
double sweep_error(const SweepRow& row);
/// Front and presets of the rows (failed rows never take part).
SweepSummary summarize_sweep(std::span<const SweepRow> rows, const SweepSummaryOptions& options);
/// The Markdown document.
std::string sweep_summary_markdown(std::span<const SweepRow> rows, const SweepSummary& summary);

}  // namespace gi
