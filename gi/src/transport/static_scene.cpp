#include "transport/static_scene.h"

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

engine::Result<std::unique_ptr<RayCaster>> make_static_caster(const BakeInput& input) {
  const RtSceneData statics = static_instances(rt_scene_from(input), nullptr);
  if (statics.instances.empty()) return engine::Error{.message = "the scene has no static mesh"};
  return make_embree_ray_caster(statics);
}

engine::Result<StaticBakeScene> prepare_static_scene(const BakeInput& input, const AtlasLayout& layout,
                                                     BakeLights lights, TexelPlacement placement) {
  StaticBakeScene b;
  b.scene = reference_scene_from(input);
  b.scene.lights = bake_lights(input, lights);
  auto index = index_reference_scene(b.scene);
  if (!index) return index.error();
  b.index = std::move(index).value();
  keep_static_emitters(b.scene, b.index);  // a dynamic object's glow moves with it: not the static bake's light
  const RtSceneData statics = static_instances(b.scene.geometry, &b.static_instance);
  if (statics.instances.empty()) return engine::Error{.message = "the scene has no static mesh to bake"};
  auto caster = make_embree_ray_caster(statics);
  if (!caster) return caster.error();
  b.caster = std::move(caster).value();
  auto texels = sample_atlas_texels(input, layout, placement, b.caster.get());
  if (!texels) return texels.error();
  b.texels = std::move(texels).value();
  return b;
}

}  // namespace gi
