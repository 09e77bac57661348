#pragma once
// Basis radiance fields in the sweep harness: knobs basis count N x SH bands x spheres x
// points per sphere face x training lights x bounces, judged against the reference path
// tracer's indirect irradiance at the dynamic objects' vertices (docs/sweeps/README.md).
// Only the scene's dynamic objects and its enabled lights take part (the static world is
// left out of both sides): what is measured is the interreflection between the objects.
// The output "field" is one row: every dynamic entity's vertices in entity order.

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "brf" method and its "brf_vertex_indirect" reference provider.
void register_brf_sweep(SweepRegistry& registry);

}  // namespace gi
