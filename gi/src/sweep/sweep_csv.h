#pragma once
// Sweep rows as CSV (RFC 4180 quoting), one row per run, and back. Columns:
//   method, scene, knob:<name> (one per knob, in order of first appearance), rel_rmse,
//   max_rel, psnr_db, fit_scale, fit_rel_rmse, bake_s, frame_ms, bytes, wall_s,
//   reference_key, status, then extra:<name> (a method's own measurements, in order of
//   first appearance; only when some row has them)
// Numbers are written in the shortest form that reads back exactly; "nan"/"inf" for
// undefined/infinite metrics; frame_ms is empty when not applicable; a knob cell is empty
// for a row whose method lacks that knob. tools/plot-sweep.py reads this format.
//   gi::write_file_atomically(dir / "atlas_cornell_box.csv", gi::sweep_csv(result.rows));
//   auto rows = gi::parse_sweep_csv(text, "atlas_cornell_box.csv");

#include <engine/result.h>

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sweep/sweep_runner.h"

namespace gi {

/// The CSV text of `rows` (header line included).
std::string sweep_csv(std::span<const SweepRow> rows);

/// Parses CSV text into records of fields (quotes, doubled quotes, CR LF handled).
/// Errors (file = `source`): an unterminated quote, text after a closing quote.
engine::Result<std::vector<std::vector<std::string>>> parse_csv(std::string_view text, const std::string& source);

/// Reads rows written by sweep_csv. Restores method, scene, knobs, rel_rmse, max_rel,
/// psnr_db, fit_scale, fit_rel_rmse, costs, wall time, reference key, status and extras. Errors:
/// malformed CSV, a missing column, a row with the wrong field count, a bad number.
engine::Result<std::vector<SweepRow>> parse_sweep_csv(std::string_view text, const std::string& source);

}  // namespace gi
