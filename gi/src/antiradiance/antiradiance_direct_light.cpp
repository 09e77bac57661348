#include "antiradiance/antiradiance_direct_light.h"

#include <engine/check.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raytrace/embree_ray_caster.h"
#include "raytrace/scene_adapter.h"

namespace gi {

engine::Result<AntiradianceDirectLight> AntiradianceDirectLight::create(const BakeInput& input,
                                                                        const AntiradianceSettings& settings) {
  if (engine::Status st = validate_bake_input(input); !st) return st.error();
  const ReferenceScene scene = reference_scene_from(input);
  auto index = index_reference_scene(scene);
  if (!index) return index.error();
  AntiradianceDirectLight out;
  out.emitters_ = point_emitters(scene, *index, std::max(settings.area_light_samples, 1), settings.seed);
  RtSceneData data = rt_scene_from(input);
  out.deforming_.assign(input.instances.size(), 0);
  for (std::size_t i = 0; i < input.instances.size() && i < data.instances.size(); ++i)
    if (input.instances[i].deforming) {
      data.instances[i].dynamic = true;
      out.deforming_[i] = 1;
    }
  auto caster = make_embree_ray_caster(data);
  if (!caster) return caster.error();
  out.caster_ = std::move(caster).value();
  return out;
}

void AntiradianceDirectLight::set_instance_transform(std::uint32_t instance, const glm::mat4& m) {
  GI_EXPECTS(instance < deforming_.size() && deforming_[instance] != 0,
             "AntiradianceDirectLight: only deforming instances move");
  caster_->set_instance_transform(instance, m);
  dirty_ = true;
}

std::vector<glm::vec3> AntiradianceDirectLight::irradiance(const ElementHierarchy& h) {
  if (dirty_) {
    caster_->commit();
    dirty_ = false;
  }
  std::vector<glm::vec3> out(h.leaf_count(), glm::vec3(0.0f));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h.leaf_count(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t l = r.begin(); l != r.end(); ++l) {
      const ElementNode& e = h.nodes[static_cast<std::size_t>(h.leaves[l])];
      glm::vec3 sum(0.0f);
      for (const PointEmitter& em : emitters_) {
        const glm::vec3 v = emitter_irradiance(em, e.center, e.normal, e.area_m2);
        if (v == glm::vec3(0.0f)) continue;
        if (emitter_visible(*caster_, em, e.center, e.normal)) sum += v;
      }
      out[l] = sum;
    }
  });
  return out;
}

}  // namespace gi
