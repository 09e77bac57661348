#include "sweep/knob_setting.h"

#include <engine/check.h>

#include <charconv>
#include <system_error>

namespace gi {

void KnobSetting::set(std::string name, std::string value) {
  for (auto& [n, v] : entries_) {
    if (n == name) {
      v = std::move(value);
      return;
    }
  }
  entries_.emplace_back(std::move(name), std::move(value));
}

bool KnobSetting::has(std::string_view name) const {
  for (const auto& e : entries_)
    if (e.first == name) return true;
  return false;
}

const std::string& KnobSetting::text(std::string_view name) const {
  for (const auto& e : entries_)
    if (e.first == name) return e.second;
  GI_EXPECTS(false, "KnobSetting::text: the method asked for a knob it did not declare");
  return entries_.front().second;  // unreachable
}

std::int64_t KnobSetting::integer(std::string_view name) const {
  const std::string& t = text(name);
  std::int64_t v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  GI_EXPECTS(r.ec == std::errc() && r.ptr == t.data() + t.size(), "KnobSetting::integer: the knob is not an integer");
  return v;
}

double KnobSetting::real(std::string_view name) const {
  const std::string& t = text(name);
  double v = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  GI_EXPECTS(r.ec == std::errc() && r.ptr == t.data() + t.size(), "KnobSetting::real: the knob is not a number");
  return v;
}

std::string KnobSetting::label() const {
  std::string s;
  for (const auto& [n, v] : entries_) s += (s.empty() ? "" : " ") + n + "=" + v;
  return s;
}

}  // namespace gi
