#pragma once
// Directional light maps in the sweep harness: knobs directions x kphotons (thousands of photons) x density x splat
// radius, judged by what they add to the image: the specular radiance the glossy static
// texels reflect of their indirect light towards the scene's camera 0, against the path
// tracer's estimate of the same quantity (reference kind "atlas_glossy_specular": the glTF
// specular lobe importance-sampled at each glossy texel, the incoming light path-traced
// without the first hit's emission, i.e. indirect light only). docs/dlm.md.

#include "sweep/sweep_registry.h"

namespace gi {

/// Adds the "atlas_glossy_specular" reference provider and the "dlm" method.
void register_dlm_sweep(SweepRegistry& registry);

}  // namespace gi
