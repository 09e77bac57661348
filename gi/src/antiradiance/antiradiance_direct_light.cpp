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
  out.deforming_.assign(input.instances.size(), 0);
  for (std::size_t i = 0; i < input.instances.size() && i < data.instances.size(); ++i)
    if (input.instances[i].deforming) {
      data.instances[i].dynamic = true;
      out.deforming_[i] = 1;
    }
  out.object_bounds_.assign(input.instances.size(), Box{glm::vec3(0.0f), glm::vec3(0.0f)});
  out.transform_.assign(input.instances.size(), glm::mat4(1.0f));
  for (std::size_t i = 0; i < input.instances.size(); ++i) {
    out.transform_[i] = input.instances[i].object_to_world;
    if (!out.deforming_[i]) continue;
    Box b{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
    for (const BakePrimitive& p : input.meshes[input.instances[i].mesh].primitives)
      for (const glm::vec3& v : p.positions) {
        b.lo = glm::min(b.lo, v);
        b.hi = glm::max(b.hi, v);
      }
    out.object_bounds_[i] = b;
  }
  auto caster = make_embree_ray_caster(data);
  if (!caster) return caster.error();
  out.caster_ = std::move(caster).value();
  return out;
}

AntiradianceDirectLight::Box AntiradianceDirectLight::world_bounds(std::uint32_t instance, const glm::mat4& m) const {
  const Box& o = object_bounds_[instance];
  Box w{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
  if (!(o.lo.x <= o.hi.x)) return w;  // an empty mesh
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? o.hi.x : o.lo.x, (c & 2) ? o.hi.y : o.lo.y, (c & 4) ? o.hi.z : o.lo.z);
    const glm::vec3 p(m * glm::vec4(corner, 1.0f));
    w.lo = glm::min(w.lo, p);
    w.hi = glm::max(w.hi, p);
  }
  const glm::vec3 margin(0.01f);
  w.lo -= margin;
  w.hi += margin;
  return w;
}

void AntiradianceDirectLight::set_instance_transform(std::uint32_t instance, const glm::mat4& m) {
  GI_EXPECTS(instance < deforming_.size() && deforming_[instance] != 0,
             "AntiradianceDirectLight: only deforming instances move");
  caster_->set_instance_transform(instance, m);
  swept_.push_back(world_bounds(instance, transform_[instance]));
  swept_.push_back(world_bounds(instance, m));
  transform_[instance] = m;
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
  swept_.clear();
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
                        if (inst >= 0 && static_cast<std::size_t>(inst) < deforming_.size() &&
                            deforming_[static_cast<std::size_t>(inst)]) {
                          todo[l] = 1;
                          continue;
                        }
                        if (swept_.empty()) continue;
                        const glm::vec3 p = h.nodes[node].center;
                        for (const PointEmitter& em : emitters_) {
                          const bool directional = em.kind == PointEmitter::Kind::Directional;
                          const glm::vec3 d = directional ? -em.direction : em.position - p;
                          const float t_max = directional ? std::numeric_limits<float>::infinity() : 1.0f;
                          for (const Box& b : swept_)
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
  swept_.clear();
  return last_;
}

}  // namespace gi
