#pragma once
// The direct light at the elements (Dachsbacher et al. 2007, §3.3 "Direct Light
// Initialization"): irradiance at every leaf centre from the scene's lights and emissive
// triangles as point emitters (transport/point_emitters.h), each shadow-tested with a ray
// caster over all mesh instances whose deforming ones follow their current transform. This
// is the one visibility test of the method: antiradiance replaces visibility only in the
// indirect transport.
//   auto direct = gi::AntiradianceDirectLight::create(input, settings).value();
//   direct.set_instance_transform(door, m);  std::vector<glm::vec3> e = direct.irradiance(h);

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <gi/bake_input.h>

#include "antiradiance/antiradiance_settings.h"
#include "antiradiance/element_hierarchy.h"
#include "raytrace/ray_caster.h"
#include "transport/point_emitters.h"

namespace gi {

class AntiradianceDirectLight {
 public:
  /// Errors: invalid input, ray caster construction failures.
  static engine::Result<AntiradianceDirectLight> create(const BakeInput& input, const AntiradianceSettings& settings);

  /// Moves deforming instance `instance` (a BakeInput index flagged deforming) in the caster;
  /// takes effect at the next irradiance().
  void set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world);
  /// Direct irradiance (W/m^2) at every leaf of `h`, in leaf order. Deterministic (each leaf
  /// on its own, any thread count).
  std::vector<glm::vec3> irradiance(const ElementHierarchy& h);

  std::size_t emitter_count() const { return emitters_.size(); }

 private:
  std::vector<PointEmitter> emitters_;
  std::unique_ptr<RayCaster> caster_;
  std::vector<char> deforming_;
  bool dirty_ = false;
};

}  // namespace gi
