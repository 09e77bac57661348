#include "raytrace/scene_adapter.h"

namespace gi {

RtSceneData rt_scene_from(const engine::Scene& scene) {
  RtSceneData data;
  for (const engine::Mesh& mesh : scene.assets.meshes) {
    RtGeometry geo;
    for (const engine::Primitive& prim : mesh.primitives) {
      const auto base = static_cast<std::uint32_t>(geo.positions.size());
      geo.positions.insert(geo.positions.end(), prim.positions.begin(), prim.positions.end());
      for (std::uint32_t i : prim.indices) geo.indices.push_back(base + i);
    }
    data.geometries.push_back(std::move(geo));
  }
  const engine::Registry& reg = scene.registry;
  reg.view<engine::MeshRenderer, engine::WorldTransform>().each(
      [&](engine::Entity e, const engine::MeshRenderer& mr, const engine::WorldTransform& wt) {
        if (mr.mesh >= data.geometries.size()) return;
        data.instances.push_back(RtInstance{mr.mesh, wt.matrix, reg.has<engine::DynamicTag>(e), e.id()});
      });
  return data;
}

}  // namespace gi
