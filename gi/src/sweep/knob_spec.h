#pragma once
// A quality knob of a GI method (samples per pixel, atlas texels per metre, SH order...):
// its name, kind, valid range and the values a sweep visits by default.
//   gi::KnobSpec spp{.name = "spp", .description = "samples per pixel", .kind = gi::KnobKind::Integer,
//                    .default_grid = {"1", "4", "16"}, .min_value = 1};

#include <engine/result.h>

#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace gi {

enum class KnobKind { Integer, Real, Choice };

struct KnobSpec {
  std::string name;                       ///< Lowercase identifier ([a-z0-9_]+), used on the command line.
  std::string description;                ///< One line, with the unit ("atlas texels per metre").
  KnobKind kind = KnobKind::Integer;      ///< How values are parsed and checked.
  std::vector<std::string> default_grid;  ///< Values swept when the command line does not override them.
  double min_value = -std::numeric_limits<double>::infinity();  ///< Inclusive bound (Integer, Real).
  double max_value = std::numeric_limits<double>::infinity();   ///< Inclusive bound (Integer, Real).
  std::vector<std::string> choices;                             ///< Allowed values (Choice).
};

/// Checks one value against the knob and returns its canonical text ("016" -> "16",
/// "0.50" -> "0.5"). Errors name the knob and the value: not a number, out of range, not a choice.
engine::Result<std::string> normalize_knob_value(const KnobSpec& knob, std::string_view text);

/// Parses a comma-separated list ("1,4,16") into canonical values; duplicates are removed,
/// the order is kept. Errors: an empty list or entry, or any value normalize_knob_value rejects.
engine::Result<std::vector<std::string>> parse_knob_values(const KnobSpec& knob, std::string_view comma_list);

/// Shortest text that reads back as exactly `v` ("0.1", "16", "inf", "nan").
std::string format_number(double v);

}  // namespace gi
