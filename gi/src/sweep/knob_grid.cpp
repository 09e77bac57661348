#include "sweep/knob_grid.h"

#include <algorithm>

namespace gi {

std::size_t KnobGrid::size() const {
  std::size_t n = 1;
  for (const auto& axis : axes) n *= axis.second.size();
  return n;
}

std::vector<KnobSetting> KnobGrid::settings() const {
  std::vector<KnobSetting> out;
  const std::size_t n = size();
  out.reserve(n);
  for (std::size_t index = 0; index < n; ++index) {
    KnobSetting s;
    std::size_t rest = index;
    std::size_t stride = n;
    for (const auto& [name, values] : axes) {
      stride /= values.size();
      s.set(name, values[rest / stride]);
      rest %= stride;
    }
    out.push_back(std::move(s));
  }
  return out;
}

engine::Result<KnobGrid> make_knob_grid(const SweepMethod& method, std::span<const std::string> overrides) {
  KnobGrid grid;
  for (const KnobSpec& k : method.knobs) {
    std::vector<std::string> values;
    for (const std::string& v : k.default_grid) {
      engine::Result<std::string> nv = normalize_knob_value(k, v);
      if (!nv) return engine::Error{"method " + method.name, "default grid of " + k.name, nv.error().message};
      values.push_back(nv.value());
    }
    grid.axes.emplace_back(k.name, std::move(values));
  }
  std::vector<std::string> seen;
  for (const std::string& o : overrides) {
    const std::size_t eq = o.find('=');
    if (eq == std::string::npos) return engine::Error{"--knob", o, "expected name=v1,v2,..."};
    const std::string name = o.substr(0, eq);
    const auto spec =
        std::find_if(method.knobs.begin(), method.knobs.end(), [&](const KnobSpec& k) { return k.name == name; });
    if (spec == method.knobs.end()) {
      std::string known;
      for (const KnobSpec& k : method.knobs) known += (known.empty() ? "" : ", ") + k.name;
      return engine::Error{"--knob", name,
                           "method '" + method.name + "' has no knob '" + name +
                               "' (its knobs: " + (known.empty() ? std::string("none") : known) + ")"};
    }
    if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
      return engine::Error{"--knob", name, "knob given twice; list all values in one --knob " + name + "=..."};
    }
    seen.push_back(name);
    engine::Result<std::vector<std::string>> values = parse_knob_values(*spec, o.substr(eq + 1));
    if (!values) return values.error();
    grid.axes[static_cast<std::size_t>(spec - method.knobs.begin())].second = std::move(values.value());
  }
  for (const auto& [name, values] : grid.axes) {
    if (values.empty()) return engine::Error{"--knob", name, "no values to sweep (the method has no default grid)"};
  }
  return grid;
}

}  // namespace gi
