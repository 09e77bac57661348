#pragma once
// `--sun` of the command-line tools, the scene extras' gi.sun in one argument
// (docs/scene-format.md): 'direction:dx,dy,dz;irradiance:R,G,B[;angular_radius_deg:D]', keys
// in any order, each once; the direction the light travels (not zero), W/m^2 (>= 0), and
// the disc's radius in [0, 45] degrees (default 0.27). It replaces the scene's sun.
//   if (!tools::set_sun(asset, "direction:0.3,-1,0.2;irradiance:700,650,600")) return usage_error;

#include <engine/scene_asset.h>
#include <engine/sun.h>

#include <optional>
#include <string>

namespace tools {

/// The sun `text` describes, or nothing when it is malformed.
std::optional<engine::Sun> parse_sun(const std::string& text);

/// Makes the sun `text` describes the scene's sun (engine::set_sun). False (scene untouched)
/// when malformed.
bool set_sun(engine::SceneAsset& scene, const std::string& text);

inline constexpr const char* kSunUsage =
    "--sun wants 'direction:dx,dy,dz;irradiance:R,G,B[;angular_radius_deg:D]': a finite, non-zero direction, "
    "irradiance >= 0 (W/m^2), a radius in [0, 45] degrees";

}  // namespace tools
