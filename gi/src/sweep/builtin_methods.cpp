#include "sweep/builtin_methods.h"

namespace gi {

void register_builtin_sweep_methods(SweepRegistry& registry) {
  (void)registry;
  // ---------------------------------------------------------------------------------------
  // REFERENCE PATH TRACER (owner: the path-tracer engineer) -- register here:
  //   1. the reference providers, e.g.
  //        registry.add_reference_provider({.kind = "camera_image", .version = "pt-1",
  //                                         .compute = <render_reference_image at the request's
  //                                                     camera/width/height/spp -> RgbField>});
  //      (and "atlas_indirect_irradiance" when the atlas texel points exist);
  //   2. the path tracer's own spp sweep as a method, e.g.
  //        registry.add_method({.name = "pathtracer", .knobs = {{.name = "spp", ...}},
  //                             .reference_for = <ReferenceRequest::camera_image(..., high spp)>,
  //                             .run = <render at ctx.knobs.integer("spp"), costs.bake_seconds = render time>});
  //   Providers must be deterministic for a given request (the result is cached on disk by
  //   scene content + kind@version + request key; bump `version` when the output changes).
  // ---------------------------------------------------------------------------------------
  //
  // GI METHODS (light atlas, PRM, DLM, BRF, antiradiance) register here as they land, one
  // add_method per method, with every quality knob declared (DESIGN.md 3, "Accuracy and its
  // cost"). No method is registered until it exists: never register stand-ins.
}

}  // namespace gi
