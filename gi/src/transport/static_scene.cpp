#include "transport/static_scene.h"

#include <cmath>

#include <engine/runtime_limits.h>

#include "raytrace/embree_ray_caster.h"
#include "raytrace/scene_adapter.h"
#include "raytrace/texel_samples.h"
#include "uv/atlas_input.h"

namespace gi {

std::vector<ReferenceLight> scene_lights(const engine::Registry& registry, BakeLights lights) {
  std::vector<ReferenceLight> kept;
  registry.view<engine::Light, engine::WorldTransform>().each(
      [&](engine::Entity, const engine::Light& light, const engine::WorldTransform& wt) {
        if (!light.enabled) return;
        if (engine::unusable_light(light, wt.matrix)) return;  // NaN or absurd at run time: as if off
        const bool keep = lights == BakeLights::Static ? !light.moves : lights == BakeLights::Moving && light.moves;
        if (keep) kept.push_back(reference_light(light, wt.matrix));
      });
  return kept;
}

std::vector<ReferenceLight> bake_lights(const BakeInput& input, BakeLights lights) {
  std::vector<ReferenceLight> kept;
  for (const BakeLight& l : input.lights) {
    if (!l.light.enabled) continue;
    const bool keep = lights == BakeLights::Static ? !l.light.moves : lights == BakeLights::Moving && l.light.moves;
    if (keep) kept.push_back(reference_light(l.light, l.light_to_world));
  }
  return kept;
}

namespace {

class SnapshotIdCaster final : public RayCaster {
 public:
  explicit SnapshotIdCaster(const StaticBakeScene& s) : s_(s) {}
  Hit intersect(const Ray& ray) const override { return mapped(s_.caster->intersect(ray)); }
  bool occluded(const Ray& ray) const override { return s_.caster->occluded(ray); }
  void intersect_many(std::span<const Ray> rays, std::span<Hit> hits) const override {
    s_.caster->intersect_many(rays, hits);
    for (Hit& h : hits) h = mapped(h);
  }
  void occluded_many(std::span<const Ray> rays, std::span<std::uint8_t> out) const override {
    s_.caster->occluded_many(rays, out);
  }
  void occluded_coherent(std::span<const Ray> rays, std::span<std::uint8_t> out) const override {
    s_.caster->occluded_coherent(rays, out);
  }
  // The casters of a StaticBakeScene are shared and const: nothing moves through this view.
  void set_instance_transform(std::uint32_t, const glm::mat4&) override {}
  void commit() override {}

 private:
  Hit mapped(Hit h) const {
    if (h.valid()) h.instance = s_.static_instance[h.instance];
    return h;
  }
  const StaticBakeScene& s_;
};

}  // namespace

std::unique_ptr<RayCaster> snapshot_id_caster(const StaticBakeScene& s) {
  return std::make_unique<SnapshotIdCaster>(s);
}

engine::Result<std::unique_ptr<RayCaster>> make_static_caster(const BakeInput& input) {
  const RtSceneData statics = static_instances(rt_scene_from(input), nullptr);
  if (statics.instances.empty()) return engine::Error{.message = "the scene has no static mesh"};
  return make_embree_ray_caster(statics);
}

engine::Result<StaticBakeScene> prepare_static_scene(const BakeInput& input, const AtlasLayout& layout,
                                                     BakeLights lights, TexelPlacement placement,
                                                     std::shared_ptr<const RayCaster> static_world) {
  StaticBakeScene b;
  b.scene = reference_scene_from(input);
  b.scene.lights = bake_lights(input, lights);
  auto index = index_reference_scene(b.scene);
  if (!index) return index.error();
  b.index = std::move(index).value();
  keep_static_emitters(b.scene, b.index);  // a dynamic object's glow moves with it: not the static bake's light
  const RtSceneData statics = static_instances(b.scene.geometry, &b.static_instance);
  if (statics.instances.empty()) return engine::Error{.message = "the scene has no static mesh to bake"};
  if (static_world) {
    b.caster = std::move(static_world);
  } else {
    auto caster = make_embree_ray_caster(statics);
    if (!caster) return caster.error();
    b.caster = std::move(caster).value();
  }
  auto texels = sample_atlas_texels(input, layout, placement, b.caster.get());
  if (!texels) return texels.error();
  b.texels = std::move(texels).value();
  drop_cut_out_texels(b, layout);
  return b;
}

TexelFootprint texel_footprint(const AtlasLayout& layout, int mesh, int triangle, std::size_t texel) {
  TexelFootprint f;
  const AtlasMeshUv& mu = layout.meshes[static_cast<std::size_t>(mesh)];
  const std::uint32_t* idx = &mu.indices[3u * static_cast<std::size_t>(triangle)];
  const glm::vec2 a0 = mu.uv1[idx[0]], a1 = mu.uv1[idx[1]], a2 = mu.uv1[idx[2]];
  const glm::mat2 m(a1 - a0, a2 - a0);  // barycentrics (u, v) -> atlas UV offset
  const float det = glm::determinant(m);
  const auto w = static_cast<float>(layout.width), h = static_cast<float>(layout.height);
  const glm::vec2 centre((static_cast<float>(texel % static_cast<std::size_t>(layout.width)) + 0.5f) / w,
                         (static_cast<float>(texel / static_cast<std::size_t>(layout.width)) + 0.5f) / h);
  if (!(std::fabs(det) > 1e-20f) || !std::isfinite(det)) {
    f.centre = glm::vec2(1.0f / 3.0f);
    return f;
  }
  const glm::mat2 inv = glm::inverse(m);
  f.centre = inv * (centre - a0);
  f.axis_u = inv * glm::vec2(1.0f / w, 0.0f);
  f.axis_v = inv * glm::vec2(0.0f, 1.0f / h);
  return f;
}

void drop_cut_out_texels(StaticBakeScene& b, const AtlasLayout& layout) {
  AtlasTexels& tx = b.texels;
  for (std::size_t i = 0; i < tx.valid.size(); ++i) {
    if (!tx.valid[i] || tx.mesh[i] < 0 || tx.triangle[i] < 0) continue;
    const RtInstance& inst = b.scene.geometry.instances[b.static_instance[static_cast<std::size_t>(tx.mesh[i])]];
    const RtGeometry& geo = b.scene.geometry.geometries[inst.geometry];
    if (!geo.cutout) continue;
    const auto tri = static_cast<std::uint32_t>(tx.triangle[i]);
    if (tri >= geo.cutout->triangle_mask.size() || geo.cutout->triangle_mask[tri] < 0) continue;
    // kCutOutPoints points of the R2 sequence (Roberts 2018) over the texel's footprint on its
    // triangle: any one kept keeps the texel. Not a regular grid: a grid's rows lock in phase
    // with a periodic cut-out (the demo's wire-mesh grille: 4 x 4 points 3.1 cm apart fell in
    // its 6.25 cm diamonds' holes at every texel, and the grille had no valid texel).
    const TexelFootprint f = texel_footprint(layout, tx.mesh[i], tx.triangle[i], i);
    constexpr int kCutOutPoints = 64;
    constexpr float kR2X = 0.7548776662f, kR2Y = 0.5698402910f;  // 1/g, 1/g^2 of the plastic constant g
    bool kept = false;
    for (int k = 0; k < kCutOutPoints && !kept; ++k) {
      const float u = std::fmod(0.5f + kR2X * static_cast<float>(k), 1.0f) - 0.5f;
      const float v = std::fmod(0.5f + kR2Y * static_cast<float>(k), 1.0f) - 0.5f;
      glm::vec2 q = f.centre + u * f.axis_u + v * f.axis_v;
      q = glm::max(q, glm::vec2(0.0f));
      if (q.x + q.y > 1.0f) q /= q.x + q.y;
      kept = !geo.cutout->cut(geo.indices, tri, q);
    }
    if (!kept) tx.valid[i] = 0;
  }
}

}  // namespace gi
