#pragma once
// The light atlas's split truth and the path tracer's cost on it, in the sweep harness: the
// provider of "atlas_split_truth" references (indirect and total irradiance of the atlas's
// texels, two path-traced estimates with different seeds; atlas_split_truth.h) and the
// "pathtracer_atlas" method (the path tracer baking the atlas at a few samples per texel),
// so that the light atlas's and the path tracer's errors and seconds are read off one table
// (tools/sweep-light-atlas-sponza.sh).
//   gi::SweepRegistry registry;
//   gi::register_atlas_truth_sweep(registry);

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "atlas_split_truth" reference provider and the "pathtracer_atlas" method.
void register_atlas_truth_sweep(SweepRegistry& registry);

}  // namespace gi
