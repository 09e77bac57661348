#include "sweep/builtin_methods.h"

#include "sweep/antiradiance_sweep.h"
#include "sweep/atlas_truth_sweep.h"
#include "sweep/brf_sweep.h"
#include "sweep/dlm_sweep.h"
#include "sweep/light_atlas_sweep.h"
#include "sweep/prm_sweep.h"
#include "sweep/reference_sweep.h"
#include "sweep/reflection_probes_sweep.h"

namespace gi {

void register_builtin_sweep_methods(SweepRegistry& registry) {
  // The reference path tracer: the camera-image and atlas-irradiance reference providers,
  // and its own spp / bounces curve ("pathtracer").
  register_reference_sweep(registry);
  register_light_atlas_sweep(registry);
  // The light atlas's split truth and the path tracer baking the atlas ("pathtracer_atlas").
  register_atlas_truth_sweep(registry);
  register_prm_sweep(registry);
  register_brf_sweep(registry);
  register_dlm_sweep(registry);
  register_antiradiance_sweep(registry);
  register_reflection_probes_sweep(registry);
  //
  // GI METHODS (light atlas, PRM, DLM, BRF, antiradiance) register here as they land, one
  // add_method per method, with every quality knob declared (DESIGN.md 3, "Accuracy and its
  // cost"). No method is registered until it exists: never register stand-ins.
}

}  // namespace gi
