#include "sweep/sweep_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sweep/knob_spec.h"

namespace gi {
namespace {

std::string fixed(double v, int digits) {
  if (std::isnan(v)) return "n/a";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, v);
  return buf;
}

std::string cost_name(SweepCost c) { return c == SweepCost::BakeSeconds ? "bake seconds" : "frame milliseconds"; }

std::string md_cell(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

}  // namespace

double sweep_cost(const SweepRow& row, SweepCost cost) {
  if (!row.ok()) return std::numeric_limits<double>::quiet_NaN();
  return cost == SweepCost::BakeSeconds ? row.costs.bake_seconds : row.costs.frame_ms;
}

double sweep_error(const SweepRow& row) {
  if (!row.ok()) return std::numeric_limits<double>::quiet_NaN();
  for (const auto& [name, value] : row.extras)
    if (name == kTruthErrorExtra) return value;
  return row.error.rel_rmse;
}

SweepSummary summarize_sweep(std::span<const SweepRow> rows, const SweepSummaryOptions& options) {
  SweepSummary s;
  s.options = options;
  for (const SweepRow& r : rows) s.points.push_back({sweep_error(r), sweep_cost(r, options.cost)});
  s.front = pareto_front(s.points);
  s.presets = choose_presets(s.points, s.front, options.targets);
  return s;
}

namespace {

// True when a run carries its error against the noise-free truth (the reference has its variance).
bool has_truth_error(std::span<const SweepRow> rows) {
  return std::any_of(rows.begin(), rows.end(), [](const SweepRow& r) {
    return std::any_of(r.extras.begin(), r.extras.end(), [](const auto& e) { return e.first == kTruthErrorExtra; });
  });
}

// The title, how to regenerate, the reference and what the columns measure.
std::string summary_intro(std::span<const SweepRow> rows, const SweepSummary& summary, bool truth) {
  std::string md;
  const std::string method = rows.empty() ? std::string("(none)") : rows.front().method;
  const std::string scene = rows.empty() ? std::string("(none)") : rows.front().scene;
  md += "# Sweep: " + md_cell(method) + " on " + md_cell(scene) + "\n\n";
  if (!summary.options.command.empty())
    md += "Regenerate (from the repository root; `gi-sweep` is `build/tools/gi-sweep/gi-sweep`):\n\n```sh\n" +
          summary.options.command + "\n```\n\n";
  if (!rows.empty()) md += "Reference: `" + rows.front().reference_key + "`\n\n";
  md +=
      "Error: relative RMSE of linear values, sqrt(sum (a-r)^2 / sum r^2) over valid elements and the three "
      "channels summed; max rel: max |a-r| / max(|r|, 0.01 mean |r|) per element (RGB norms); PSNR of the "
      "tonemapped images (dB); fit: after the least-squares scale s. Trade-off cost: " +
      cost_name(summary.options.cost) + ".\n\n";
  if (truth)
    md +=
        "The reference carries its own sampling variance v per element: ref_noise = sqrt(sum v / sum r^2) is its "
        "relative RMSE from the truth, and truth_rel_rmse = sqrt(max(0, sum (a-r)^2 - sum v) / (sum r^2 - sum v)) "
        "the error against the noise-free truth (both sums unbiased when the method's noise is independent of the "
        "reference's). The front and the presets use truth_rel_rmse.\n\n";

  return md;
}

// "## Runs": one row per run, its knobs, errors, costs, front and preset marks and extras.
std::string runs_table(std::span<const SweepRow> rows, const SweepSummary& summary) {
  std::vector<std::string> knobs;
  for (const SweepRow& r : rows)
    for (const auto& e : r.knobs.entries())
      if (std::find(knobs.begin(), knobs.end(), e.first) == knobs.end()) knobs.push_back(e.first);
  std::vector<std::string> extras;
  for (const SweepRow& r : rows)
    for (const auto& e : r.extras)
      if (std::find(extras.begin(), extras.end(), e.first) == extras.end()) extras.push_back(e.first);
  auto extra_cell = [](const SweepRow& r, const std::string& name) {
    for (const auto& e : r.extras)
      if (e.first == name) return fixed(e.second, 4);
    return std::string();
  };
  auto preset_of = [&](std::size_t i) {
    std::string names;
    for (const PresetChoice& p : summary.presets)
      if (p.index == i) names += (names.empty() ? "" : ", ") + p.name + (p.target_met ? "" : " (target not met)");
    return names;
  };
  auto on_front = [&](std::size_t i) {
    return std::find(summary.front.begin(), summary.front.end(), i) != summary.front.end();
  };

  std::string md;
  md += "## Runs\n\n|";
  for (const std::string& k : knobs) md += " " + md_cell(k) + " |";
  md += " rel RMSE | max rel | PSNR dB | fit s | fit rel RMSE | bake s | frame ms | bytes | front | preset | status |";
  for (const std::string& e : extras) md += " " + md_cell(e) + " |";
  md += "\n|";
  for (std::size_t i = 0; i < knobs.size() + 11 + extras.size(); ++i) md += "---|";
  md += "\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const SweepRow& r = rows[i];
    md += "|";
    for (const std::string& k : knobs) md += " " + (r.knobs.has(k) ? md_cell(r.knobs.text(k)) : std::string()) + " |";
    md += " " + fixed(r.error.rel_rmse, 4) + " | " + fixed(r.error.max_rel, 4) + " | " + fixed(r.error.psnr_db, 4) +
          " | " + fixed(r.error.fit_scale, 4) + " | " + fixed(r.error.fit_rel_rmse, 4) + " | " +
          fixed(r.costs.bake_seconds, 4) + " | " + fixed(r.costs.frame_ms, 4) + " | " + std::to_string(r.costs.bytes) +
          " | " + (on_front(i) ? "yes" : "") + " | " + preset_of(i) + " | " + md_cell(r.status) + " |";
    for (const std::string& e : extras) md += " " + extra_cell(r, e) + " |";
    md += "\n";
  }

  return md;
}

// "## Pareto front" and "## Suggested presets".
std::string front_and_presets(std::span<const SweepRow> rows, const SweepSummary& summary, bool truth) {
  std::string md;
  const std::string error_name = truth ? "truth_rel_rmse" : "rel RMSE";
  md += "\n## Pareto front\n\nRuns no other run beats on both " + error_name + " and " +
        cost_name(summary.options.cost) + " (failed runs excluded), cheapest first:\n\n";
  if (summary.front.empty()) md += "(empty: no run produced a valid error and cost)\n";
  for (std::size_t i : summary.front) {
    md += "- " + (rows[i].knobs.label().empty() ? std::string("(no knobs)") : rows[i].knobs.label()) + ": " +
          error_name + " " + fixed(summary.points[i].error, 4) + ", " + fixed(summary.points[i].cost, 4) + " " +
          (summary.options.cost == SweepCost::BakeSeconds ? "s" : "ms") + "\n";
  }

  const PresetTargets& t = summary.options.targets;
  md += "\n## Suggested presets\n\nRule: each preset is the cheapest Pareto-front run whose " + error_name +
        " is at or "
        "below its target (preview " +
        format_number(t.preview) + ", medium " + format_number(t.medium) + ", high " + format_number(t.high) +
        "); when no front run reaches a target, the most accurate front run is suggested and "
        "marked \"target not met\".\n\n";
  if (summary.presets.empty()) md += "(none: the front is empty)\n";
  for (const PresetChoice& p : summary.presets) {
    const SweepRow& r = rows[p.index];
    md += "- **" + p.name + "**: " + (r.knobs.label().empty() ? std::string("(no knobs)") : r.knobs.label()) + " (" +
          error_name + " " + fixed(summary.points[p.index].error, 4) + ", " + fixed(summary.points[p.index].cost, 4) +
          " " + (summary.options.cost == SweepCost::BakeSeconds ? "s" : "ms") + ")" +
          (p.target_met ? "" : " -- target " + format_number(p.target) + " not met") + "\n";
  }
  return md;
}

}  // namespace

std::string sweep_summary_markdown(std::span<const SweepRow> rows, const SweepSummary& summary) {
  const bool truth = has_truth_error(rows);
  return summary_intro(rows, summary, truth) + runs_table(rows, summary) + front_and_presets(rows, summary, truth);
}

}  // namespace gi
