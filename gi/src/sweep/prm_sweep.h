#pragma once
// PRM in the sweep harness: knobs entry points x clusters x active clusters K x pane
// density x splitting factor x light pose, judged against the reference path tracer's
// per-texel indirect irradiance with the moving light at the same pose
// (docs/sweeps/README.md). Poses: "authored" (as in the scene file), "corner" (low in a
// corner of the static bounds, facing the centre), "wall" (1 cm from the +x wall of the
// static bounds, shining down along it).

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "prm" method and its "atlas_indirect_irradiance_posed" reference provider.
void register_prm_sweep(SweepRegistry& registry);

}  // namespace gi
