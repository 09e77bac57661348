#pragma once
// The glossy static texels a camera sees and the path-traced truth of what their specular
// lobe reflects, shared by the sweeps of the methods that draw that lobe (directional light
// maps, reflection probes): docs/dlm.md, docs/reflection_probes.md.
//   auto g = gi::glossy_texels(scene, 8.0, 0.15, &request);   // the layout at 8 texels/m
//   if (g->glossy[t]) { /* texel t: g->s.texels.position[t], g->brdf[t], seen from g->eye */ }

#include <engine/gltf_brdf.h>
#include <engine/result.h>
#include <engine/scene_asset.h>
#include <gi/reference.h>
#include <gi/rgb_field.h>

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "sweep/sweep_method.h"
#include "transport/static_scene.h"

namespace gi {

/// The static scene at one atlas layout, camera 0's position, and per texel whether it is
/// glossy (roughness below glossy_threshold(), the bake's rule) and faces the camera, and its BRDF.
struct GlossyTexels {
  StaticBakeScene s;
  glm::vec3 eye{0.0f};
  std::vector<std::uint8_t> glossy;  ///< Per atlas texel: glossy and facing the camera.
  std::vector<engine::GltfBrdf> brdf;
};

/// Every material of roughness below 0.35 (the planner's old glossy threshold: glossy_room's
/// and the demo corridor's floors) set to `floor_roughness`.
engine::SceneAsset with_floor_roughness(const engine::SceneAsset& asset, double floor_roughness);
/// The glossy threshold of the bake and the reference for that floor: above it, at least 0.35.
double glossy_threshold(double floor_roughness);

/// Where the eye is: camera 0, or 1.7 m above the glossy texels' centroid along their mean
/// normal (a player standing on the glossy floor: the views from above that a camera far
/// away does not have, e.g. the demo corridor's floor, which camera 0 sees only at grazing).
enum class GlossyView { Camera0, Above };

/// The glossy texels of `scene` (its floor at `floor_roughness`) at `density` texels/m that
/// camera 0 sees, their samples placed as `placement` says (gi/reference.h): Raster puts the
/// samples of a floor's border texels on the line where the walls begin, and lobe rays from
/// there slip behind the walls; VisibleSurface keeps them on the floor a camera sees.
/// `request`, when given, names the errors.
engine::Result<GlossyTexels> glossy_texels(const SweepScene& scene, double density, double floor_roughness,
                                           const ReferenceRequest* request,
                                           TexelPlacement placement = TexelPlacement::Raster,
                                           GlossyView view = GlossyView::Camera0);

/// What reaches the texel along a sampled lobe direction.
enum class LobeRadiance {
  Reflected,  ///< PathTracer::reflected_radiance: without the first hit's emission and sky (indirect light).
  Full,       ///< PathTracer::radiance: with them (what a reflection probe captures).
};

/// The path-traced specular radiance each glossy texel reflects towards the eye: the glTF
/// specular lobe importance-sampled (`request` params "texels_per_m", "spp",
/// "floor_roughness"; "placement" = "visible_surface" for TexelPlacement::VisibleSurface,
/// else Raster; "view" = "above" for GlossyView::Above, else camera 0), its per-texel
/// sampling variance kept so that compare_rgb removes the reference's noise. Deterministic
/// in the request (its own random streams).
engine::Result<RgbField> glossy_specular_truth(const ReferenceJob& job, LobeRadiance what);

}  // namespace gi
