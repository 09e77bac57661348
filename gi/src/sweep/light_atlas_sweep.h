#pragma once
// The light atlas in the sweep harness: knobs vpls x bounces x density (texels per metre),
// judged against the reference path tracer's per-texel indirect irradiance at the same
// density (docs/sweeps/README.md).

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "light_atlas" method.
void register_light_atlas_sweep(SweepRegistry& registry);

}  // namespace gi
