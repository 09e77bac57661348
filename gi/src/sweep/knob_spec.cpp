#include "sweep/knob_spec.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>

namespace gi {
namespace {

engine::Error knob_error(const KnobSpec& knob, std::string message) {
  return engine::Error{"--knob", knob.name, std::move(message)};
}

}  // namespace

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

engine::Result<std::string> normalize_knob_value(const KnobSpec& knob, std::string_view text) {
  if (text.empty()) return knob_error(knob, "empty value");
  if (knob.kind == KnobKind::Choice) {
    if (std::find(knob.choices.begin(), knob.choices.end(), text) == knob.choices.end()) {
      std::string allowed;
      for (const std::string& c : knob.choices) allowed += (allowed.empty() ? "" : ", ") + c;
      return knob_error(knob, "'" + std::string(text) + "' is not one of: " + allowed);
    }
    return std::string(text);
  }
  double v = 0.0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || !std::isfinite(v)) {
    return knob_error(knob, "'" + std::string(text) + "' is not a finite number");
  }
  if (knob.kind == KnobKind::Integer && (v != std::floor(v) || std::abs(v) > 9.0e15)) {
    return knob_error(knob, "'" + std::string(text) + "' is not an integer");
  }
  if (v < knob.min_value || v > knob.max_value) {
    return knob_error(knob, "'" + std::string(text) + "' is outside [" + format_number(knob.min_value) + ", " +
                                format_number(knob.max_value) + "]");
  }
  return format_number(v);
}

engine::Result<std::vector<std::string>> parse_knob_values(const KnobSpec& knob, std::string_view list) {
  std::vector<std::string> values;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = list.find(',', start);
    const std::string_view item = list.substr(start, comma == std::string_view::npos ? list.npos : comma - start);
    engine::Result<std::string> v = normalize_knob_value(knob, item);
    if (!v) return v.error();
    if (std::find(values.begin(), values.end(), v.value()) == values.end()) values.push_back(v.value());
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return values;
}

}  // namespace gi
