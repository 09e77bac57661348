#include "system/sky_visibility.h"

#include <engine/components.h>
#include <engine/sky.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/color.h"
#include "raytrace/ray.h"
#include "transport/static_scene.h"

namespace gi {

namespace {

const glm::vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

}  // namespace

engine::Result<std::unique_ptr<SkyVisibility>> SkyVisibility::create(const engine::Scene& scene,
                                                                     std::shared_ptr<const RayCaster> static_world) {
  if (!static_world) {
    auto caster = make_static_caster(bake_input_from(scene));
    if (!caster) return caster.error();
    static_world = std::move(caster).value();
  }
  std::unique_ptr<SkyVisibility> out(new SkyVisibility());
  out->registry_ = &scene.registry;
  out->caster_ = std::move(static_world);
  const engine::Environment& env = scene.assets.environment;
  // Spherical Fibonacci directions: equal solid angle each.
  const float golden = std::numbers::pi_v<float> * (3.0f - std::sqrt(5.0f));
  for (int i = 0; i < kDirections; ++i) {
    const float y = 1.0f - (2.0f * static_cast<float>(i) + 1.0f) / static_cast<float>(kDirections);
    const float r = std::sqrt(std::max(0.0f, 1.0f - y * y));
    const float phi = golden * static_cast<float>(i);
    const glm::vec3 d(r * std::cos(phi), y, r * std::sin(phi));
    out->directions_.push_back(d);
    out->sky_weight_.push_back(luminance(engine::sky_radiance(env.sky_radiance, env.sky_gradient, d)));
  }
  for (const engine::Mesh& m : scene.assets.meshes) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const engine::Primitive& p : m.primitives)
      for (const glm::vec3& v : p.positions) {
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
      }
    if (lo.x > hi.x) lo = hi = glm::vec3(0.0f);
    out->mesh_bounds_.emplace_back(lo, hi);
  }
  return out;
}

std::array<float, 6> SkyVisibility::measure(const glm::vec3& point) const {
  double seen[6] = {}, all[6] = {};
  for (std::size_t i = 0; i < directions_.size(); ++i) {
    const glm::vec3& d = directions_[i];
    if (!(sky_weight_[i] > 0.0f)) continue;
    const bool open = !caster_->occluded(Ray{point, 0.0f, d, std::numeric_limits<float>::infinity()});
    for (int a = 0; a < 6; ++a) {
      const float w = sky_weight_[i] * std::max(0.0f, glm::dot(d, kAxes[a]));
      all[a] += static_cast<double>(w);
      if (open) seen[a] += static_cast<double>(w);
    }
  }
  std::array<float, 6> v{};
  for (int a = 0; a < 6; ++a)
    v[static_cast<std::size_t>(a)] = all[a] > 0.0 ? static_cast<float>(seen[a] / all[a]) : 1.0f;
  return v;
}

std::size_t SkyVisibility::update() {
  const engine::Registry& registry = *registry_;
  std::size_t measured = 0;
  registry.view<engine::MeshRenderer, engine::WorldTransform>().each(
      [&](engine::Entity e, const engine::MeshRenderer& mr, const engine::WorldTransform& wt) {
        if (registry.has<engine::StaticTag>(e) || mr.mesh >= mesh_bounds_.size()) return;
        auto [it, fresh] = entries_.try_emplace(e.id());
        if (!fresh && it->second.matrix == wt.matrix) return;
        const auto& [lo, hi] = mesh_bounds_[mr.mesh];
        it->second.matrix = wt.matrix;
        it->second.axes = measure(glm::vec3(wt.matrix * glm::vec4(0.5f * (lo + hi), 1.0f)));
        ++measured;
      });
  return measured;
}

bool SkyVisibility::get(engine::Entity e, float (&axes)[6]) const {
  const auto it = entries_.find(e.id());
  if (it == entries_.end()) return false;
  for (int a = 0; a < 6; ++a) axes[a] = it->second.axes[static_cast<std::size_t>(a)];
  return true;
}

}  // namespace gi
