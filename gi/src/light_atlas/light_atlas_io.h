#pragma once
// Saving a light-atlas bake into a bundle directory and loading it back for a scene.
//   gi::save_light_atlas("level.gibake", bake, input);
//   auto bake = gi::load_light_atlas("level.gibake", input);   // checks the geometry hash
//
// Files (DESIGN.md §5):
//   light_atlas.exr        RGBA float32, width x height of the layout, texel (x, y) at row y
//                          column x: RGB = irradiance (W/m^2), A = 1 where valid, else 0.
//   light_atlas_vpls.bin   settings + VPL solution (light_atlas_vpl_file.h).
//   manifest.json          methods.light_atlas = {
//     "files":    { "irradiance": {"file": "light_atlas.exr", "xxh3_64": "<hex>"},
//                   "vpls":       {"file": "light_atlas_vpls.bin", "xxh3_64": "<hex>"} },
//     "direct_light": "unlit" (the atlas holds, besides indirect light, the direct light the
//                     renderer does not draw: the sky's and that of emitters no light stands
//                     for) or "all" (settings.include_direct: every static source's);
//                     a bundle without it predates the baked sky and does not load,
//     "settings": { LightAtlasSettings' scalar fields but threads },
//     "layout":   { "requested_texels_per_metre", "texels_per_metre", "padding_texels", "width", "height" },
//     "stats":    { LightAtlasStats' counts (timings: bake_stats.json) } }
// The manifest is written last and names the XXH3-64 of both files, so a bundle whose
// bake was interrupted between files, or mixes files of two bakes, does not load.

#include <engine/result.h>
#include <gi/bake_input.h>

#include <filesystem>
#include <string>

#include "light_atlas/light_atlas.h"

namespace gi {

inline constexpr const char* kLightAtlasMethod = "light_atlas";
inline constexpr const char* kLightAtlasExrFile = "light_atlas.exr";
inline constexpr const char* kLightAtlasVplsFile = "light_atlas_vpls.bin";
/// The atlas layout (bundle/atlas_layout_file.h), files.layout.
inline constexpr const char* kLightAtlasLayoutFile = "light_atlas_layout.bin";

/// Writes `bake` of `input` into `bundle_dir` (created if needed): the EXR, the VPL file,
/// then the manifest's "light_atlas" entry with the input's static_lights_hash (other
/// methods' entries are kept when the manifest has the same geometry hash). Every file is written to a temporary name
/// and renamed. Error when the bake's arrays do not match its size, or a file cannot be written.
engine::Status save_light_atlas(const std::filesystem::path& bundle_dir, const LightAtlasBake& bake,
                                const BakeInput& input);

/// Loads the light atlas of `bundle_dir` for `input`: rejects a stale bundle (geometry hash
/// differs from scene_geometry_hash(input), or the atlas was baked under other static lights:
/// static_lights_hash), rebuilds the layout from atlas_inputs_from(input)
/// with the manifest's requested density and padding, and checks every file against the
/// manifest (checksums, sizes, finite non-negative irradiance, alpha 0 or 1). Every error
/// names the file and the problem.
engine::Result<LightAtlasBake> load_light_atlas(const std::filesystem::path& bundle_dir, const BakeInput& input);

}  // namespace gi
