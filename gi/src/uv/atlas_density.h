#pragma once
// The light-atlas texel density of each bake preset. Every method that writes atlas texels
// (the light atlas, the PRM) must use one layout, so the density is a property of the
// preset's shared layout, not of one method.
//   float density = gi::atlas_density_preset("medium").value();   // texels per metre

#include <string_view>

#include <engine/result.h>

namespace gi {

/// Texels per metre of "preview", "medium" or "high". Error: another name.
engine::Result<float> atlas_density_preset(std::string_view preset);

}  // namespace gi
