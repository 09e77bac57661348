#pragma once
// What every baker of the static world reads: the path tracer's snapshot of the scene
// (triangles, materials, lights), a ray caster over the static instances only (dynamic
// objects move, so they must not shadow baked data) and the light-atlas texels the bake
// fills (its reference points).
//   auto s = gi::prepare_static_scene(input, layout, gi::BakeLights::Static).value();
//   bool lit = !s.caster->occluded(ray);

#include <engine/registry.h>
#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/reference.h>

#include <memory>

#include "raytrace/ray_caster.h"
#include "raytrace/reference_scene.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi {

/// Which of the scene's enabled lights the snapshot keeps.
enum class BakeLights : std::uint8_t {
  Static,  ///< Lights that do not move (the light atlas bakes them; moving ones are PRM's).
  Moving,  ///< Lights flagged as moving (the flashlight, scripted lamps).
  None,    ///< No light (PRM panes are light-independent).
};

struct StaticBakeScene {
  ReferenceScene scene;
  ReferenceSceneIndex index;
  std::shared_ptr<const RayCaster> caster;  ///< Static instances only.
  /// Caster instance -> snapshot instance (scene.geometry.instances index).
  std::vector<std::uint32_t> static_instance;
  AtlasTexels texels;  ///< The layout's texels.

  /// The index.triangles entry a hit of `caster` landed on.
  std::uint32_t triangle_of(const Hit& hit) const {
    return index.instance_first[static_instance[hit.instance]] + hit.primitive;
  }
};

/// `s.caster` with the snapshot's instance ids: every hit's `instance` becomes
/// s.static_instance[hit.instance], so that s.index.instance_first[hit.instance] finds the
/// triangle it landed on. PathTracer indexes its ReferenceSceneIndex by the caster's ids: built
/// on a StaticBakeScene it needs this view (with s.caster itself, a scene whose dynamic
/// instances come before static ones shades hits on the wrong triangles). `s` must outlive it;
/// it moves nothing (set_instance_transform and commit do nothing).
std::unique_ptr<RayCaster> snapshot_id_caster(const StaticBakeScene& s);

/// Errors: invalid scene data (non-finite values...), no static mesh instance.
/// `placement`: where the texels' samples lie (gi/reference.h). `static_world`: a caster the
/// caller already built over the same static instances (make_static_caster of `input`),
/// shared instead of building a second one.
engine::Result<StaticBakeScene> prepare_static_scene(const BakeInput& input, const AtlasLayout& layout,
                                                     BakeLights lights,
                                                     TexelPlacement placement = TexelPlacement::Raster,
                                                     std::shared_ptr<const RayCaster> static_world = nullptr);

/// A light-atlas texel's footprint on its triangle in barycentrics (u, v): its centre and
/// the offsets of one texel step along the atlas's x and y (the texel covers centre +-
/// axis_u / 2 +- axis_v / 2). Degenerate atlas triangles give the centroid and zero axes.
struct TexelFootprint {
  glm::vec2 centre{0.0f};
  glm::vec2 axis_u{0.0f};
  glm::vec2 axis_v{0.0f};
};
TexelFootprint texel_footprint(const AtlasLayout& layout, int mesh, int triangle, std::size_t texel);

/// Marks the texels wholly cut out (alpha MASK / BLEND, none of 64 low-discrepancy points over
/// the texel's footprint kept) as not valid: nothing there to light. prepare_static_scene runs it.
void drop_cut_out_texels(StaticBakeScene& scene, const AtlasLayout& layout);

/// A ray caster over the static mesh instances of `input` (what a runtime relighting of the
/// static world shadows with). Errors: no static instance, invalid data.
engine::Result<std::unique_ptr<RayCaster>> make_static_caster(const BakeInput& input);

/// The lights of `input` of the given kind, as the path tracer sees them, in order.
std::vector<ReferenceLight> bake_lights(const BakeInput& input, BakeLights lights);

/// The enabled lights of a live `registry` of the given kind, as the path tracer sees them,
/// in registry order: what the runtime relights with every frame. Cheap: no geometry is read.
std::vector<ReferenceLight> scene_lights(const engine::Registry& registry, BakeLights lights);

}  // namespace gi
