#pragma once
// The light atlas's texel samples as every baker and the reference path tracer take them.
// rasterize_atlas (gi/src/uv) places a sample on its texel's triangle without knowing the
// rest of the scene, so where a chart runs under or behind other geometry — a floor that
// continues under a wall, a wall's end hidden in another wall — a texel's sample can lie
// inside that geometry and see it from behind: dark scallops along concave edges once
// bilinear filtering spreads it. Here each sample looks around itself within its texel's
// footprint; a back face there means the sample is inside or behind a surface, and it
// moves just in front of it (as production lightmappers do).
//   gi::AtlasTexels texels = gi::sample_atlas_texels(input, layout).value();

#include <cstddef>
#include <cstdint>
#include <vector>

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/reference.h>

#include "raytrace/ray_caster.h"
#include "raytrace/rt_scene_data.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi {

struct TexelRelocationStats {
  std::size_t checked = 0;  ///< Valid texels looked at.
  std::size_t moved = 0;    ///< Samples that were inside or behind geometry and moved out.
};

/// For every valid texel: 8 rays from its sample along the surface (tilted slightly off
/// it) reaching one texel (1 / texels_per_metre); the nearest hit on a back face moves the
/// sample to just in front of that face. `statics` holds the static geometry the texels
/// belong to. Deterministic (no randomness; per-texel work).
TexelRelocationStats relocate_texel_samples(AtlasTexels& texels, float texels_per_metre, const RayCaster& statics);

/// The texels of `layout` for the static instances of `input`, placed as asked: Raster is
/// rasterize_atlas; VisibleSurface rasterizes with samples 0.05 texel inside their
/// triangles, then relocate_texel_samples against the static instances (a caster of them is
/// built when `statics` is null).
inline constexpr float kVisibleSurfaceInsetTexels = 0.05f;
engine::Result<AtlasTexels> sample_atlas_texels(const BakeInput& input, const AtlasLayout& layout,
                                                TexelPlacement placement, const RayCaster* statics = nullptr,
                                                TexelRelocationStats* stats = nullptr);

/// The static (non-dynamic) instances of `data`, with per kept instance its index in `data`.
RtSceneData static_instances(const RtSceneData& data, std::vector<std::uint32_t>* kept = nullptr);

}  // namespace gi
