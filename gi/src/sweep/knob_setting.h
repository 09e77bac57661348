#pragma once
// One assignment of values to a method's knobs: what a single sweep run renders with.
//   int spp = static_cast<int>(ctx.knobs.integer("spp"));
//   std::cout << ctx.knobs.label();  // "spp=16 bounces=2"

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace gi {

class KnobSetting {
 public:
  /// Sets (or replaces) a knob's canonical value text.
  void set(std::string name, std::string value);
  /// True when the knob has a value.
  bool has(std::string_view name) const;
  /// The value text. Precondition: has(name).
  const std::string& text(std::string_view name) const;
  /// The value as an integer. Preconditions: has(name) and the text is an integer.
  std::int64_t integer(std::string_view name) const;
  /// The value as a real number. Preconditions: has(name) and the text is a number.
  double real(std::string_view name) const;
  /// (name, value) pairs in the method's knob order.
  const std::vector<std::pair<std::string, std::string>>& entries() const { return entries_; }
  /// "name=value name=value", for progress and logs.
  std::string label() const;

  bool operator==(const KnobSetting&) const = default;

 private:
  std::vector<std::pair<std::string, std::string>> entries_;
};

}  // namespace gi
