#include "antiradiance/antiradiance_direct_light.h"

#include <engine/check.h>
#include <engine/segment_box.h>

#include <algorithm>
#include <limits>

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
  out.moving_ = MovingInstances::mark(input, data);
  auto caster = make_embree_ray_caster(data);
  if (!caster) return caster.error();
  out.caster_ = std::move(caster).value();
  return out;
}

void AntiradianceDirectLight::set_instance_transform(std::uint32_t instance, const glm::mat4& m) {
  GI_EXPECTS(moving_.deforming(static_cast<std::int32_t>(instance)),
             "AntiradianceDirectLight: only deforming instances move");
  caster_->set_instance_transform(instance, m);
  moving_.move(instance, m);
  dirty_ = true;
}

void AntiradianceDirectLight::compute(const ElementHierarchy& h, const std::vector<char>& todo,
                                      std::vector<glm::vec3>& out) const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h.leaf_count(), 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t l = r.begin(); l != r.end(); ++l) {
                        if (!todo.empty() && !todo[l]) continue;
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
}

std::vector<glm::vec3> AntiradianceDirectLight::irradiance(const ElementHierarchy& h) {
  if (dirty_) {
    caster_->commit();
    dirty_ = false;
  }
  moving_.clear_swept();
  last_.assign(h.leaf_count(), glm::vec3(0.0f));
  compute(h, {}, last_);
  last_recomputed_ = h.leaf_count();
  return last_;
}

const std::vector<glm::vec3>& AntiradianceDirectLight::update(const ElementHierarchy& h) {
  if (last_.size() != h.leaf_count()) {
    irradiance(h);
    return last_;
  }
  if (dirty_) {
    caster_->commit();
    dirty_ = false;
  }
  std::vector<char> todo(h.leaf_count(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h.leaf_count(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t l = r.begin(); l != r.end(); ++l) {
                        const auto node = static_cast<std::size_t>(h.leaves[l]);
                        const std::int32_t inst = h.node_instance[node];
                        if (moving_.deforming(inst)) {
                          todo[l] = 1;
                          continue;
                        }
                        if (moving_.swept().empty()) continue;
                        const glm::vec3 p = h.nodes[node].center;
                        for (const PointEmitter& em : emitters_) {
                          const bool directional = em.kind == PointEmitter::Kind::Directional;
                          const glm::vec3 d = directional ? -em.direction : em.position - p;
                          const float t_max = directional ? std::numeric_limits<float>::infinity() : 1.0f;
                          for (const MovingInstances::Box& b : moving_.swept())
                            if (engine::segment_meets_box(p, d, t_max, b.lo, b.hi)) {
                              todo[l] = 1;
                              break;
                            }
                          if (todo[l]) break;
                        }
                      }
                    });
  last_recomputed_ = static_cast<std::size_t>(std::count(todo.begin(), todo.end(), 1));
  compute(h, todo, last_);
  moving_.clear_swept();
  return last_;
}

}  // namespace gi
