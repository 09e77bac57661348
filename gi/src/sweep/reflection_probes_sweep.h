#pragma once
// Reflection probes in the sweep harness (docs/reflection_probes.md, "Accuracy"): knobs
// resolution x supersample x prefilter samples x the light atlas they capture, judged by
// what they add to the image: the specular radiance the glossy static texels reflect towards
// camera 0 (the probes' lookup with box parallax and roughness mip, times the split sum's
// directional albedo, as the forward shader computes it), against the path tracer's same
// lobe (reference kind "probe_glossy_specular": PathTracer::radiance along the importance-
// sampled glTF specular lobe, which holds the first hit's emission and sky as a probe does).
// Errors inside the probes' volumes and at their borders are reported apart.

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "probe_glossy_specular" reference provider and the "reflection_probes" method.
void register_reflection_probes_sweep(SweepRegistry& registry);

}  // namespace gi
