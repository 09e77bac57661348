#pragma once
// The grid of knob settings a sweep visits: each knob's default values, replaced by
// command-line overrides "name=v1,v2,...", expanded as a Cartesian product.
//   auto grid = gi::make_knob_grid(method, {"spp=1,4,16"});
//   for (const gi::KnobSetting& s : grid->settings()) run(s);

#include <engine/result.h>

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sweep/knob_setting.h"
#include "sweep/sweep_method.h"

namespace gi {

struct KnobGrid {
  /// One axis per knob, in the method's knob order: (name, values).
  std::vector<std::pair<std::string, std::vector<std::string>>> axes;

  /// Number of settings (product of the axis lengths; 1 for a method without knobs).
  std::size_t size() const;
  /// Every setting; the first knob varies slowest.
  std::vector<KnobSetting> settings() const;
};

/// Builds the grid of `method`. Errors (file "--knob"): an override without '=', an unknown
/// knob (the message lists the method's knobs), a knob given twice, a bad value.
engine::Result<KnobGrid> make_knob_grid(const SweepMethod& method, std::span<const std::string> overrides);

}  // namespace gi
