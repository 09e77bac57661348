#pragma once
// The reference path tracer in the sweep harness: the providers of the two reference kinds
// (camera images, indirect irradiance of light-atlas texels) and the path tracer's own
// accuracy-vs-time curve as a method ("pathtracer": spp and bounces against a converged
// render).
//   gi::SweepRegistry registry;
//   gi::register_reference_sweep(registry);

#include <gi/bake_input.h>

#include "sweep/sweep_registry.h"

namespace gi {

/// Samples per pixel of the converged camera reference the "pathtracer" method is measured
/// against. Its own noise is 1/64 of a 1-spp render's: errors measured at 1024 spp read
/// about 12% high.
inline constexpr int kConvergedReferenceSpp = 4096;

void register_reference_sweep(SweepRegistry& registry);

/// What the light atlas bakes, and so the world of its "atlas_indirect_irradiance"
/// reference: `input` without the lights that move (the PRM's) and the dynamic instances
/// (BRF's). Deforming regions stay (baked at their authored pose).
BakeInput static_world(BakeInput input);

}  // namespace gi
