#pragma once
// How much of the sky a dynamic mesh entity sees, for the renderer's sky term
// (engine::IndirectLightFrame::sky_visibility). The renderer draws the sky as unshadowed
// ambient light; static surfaces get their sky occlusion from a bake (the light atlas with
// --include-direct), dynamic ones have none. Here, per dynamic mesh entity, an ambient cube
// of sky visibility measured at the centre of its world bounds: for each axis a of +-X, +-Y,
// +-Z, the share of the unoccluded sky irradiance on a surface facing a that arrives past
// the static world,
//   V_a = sum_d L(d) max(d.a, 0) vis(d) / sum_d L(d) max(d.a, 0),
// over 256 fixed directions d (a spherical Fibonacci set), L the sky's radiance (uniform +
// gradient, engine/sky.h), vis a shadow ray against the static geometry. Recomputed only for
// entities whose world transform changed. Deterministic; no GL.
//   auto sky = gi::SkyVisibility::create(scene).value();   // the scene outlives it
//   sky->update();   // each frame: only the entities that moved are measured again
//   float axes[6]; sky->get(entity, axes);

#include <engine/entity.h>
#include <engine/result.h>
#include <engine/scene.h>

#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "raytrace/ray_caster.h"

namespace gi {

class SkyVisibility {
 public:
  static constexpr int kDirections = 256;

  /// For the dynamic mesh entities of `scene` (MeshRenderer without StaticTag), against its
  /// static instances, under its sky (scene.assets.environment).
  /// `static_world`: the static world's ray caster when the caller has one (GISystem shares
  /// one between its methods); built from `scene` otherwise.
  static engine::Result<std::unique_ptr<SkyVisibility>> create(const engine::Scene& scene,
                                                               std::shared_ptr<const RayCaster> static_world = nullptr);

  /// Re-measures the scene's entities that moved (or appeared); returns how many were measured.
  std::size_t update();

  /// +X, -X, +Y, -Y, +Z, -Z; false when `e` was never measured.
  bool get(engine::Entity e, float (&axes)[6]) const;

  /// One measurement at `point` (exposed for tests).
  std::array<float, 6> measure(const glm::vec3& point) const;

 private:
  SkyVisibility() = default;
  const engine::Registry* registry_ = nullptr;
  std::shared_ptr<const RayCaster> caster_;
  std::vector<glm::vec3> directions_;
  std::vector<float> sky_weight_;                             ///< Luminance of the sky's radiance of each direction.
  std::vector<std::pair<glm::vec3, glm::vec3>> mesh_bounds_;  ///< Object-space box per asset mesh.
  struct Entry {
    glm::mat4 matrix{0.0f};
    std::array<float, 6> axes{};
  };
  std::unordered_map<std::uint64_t, Entry> entries_;
};

}  // namespace gi
