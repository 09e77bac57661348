#pragma once
// The fingerprint of what a bake depends on, stored in the bundle's manifest so a bundle
// baked from other geometry or materials is reported as stale instead of silently used.
//   if (manifest.geometry_hash != gi::scene_geometry_hash(input)) { /* stale bundle */ }

#include <gi/bake_input.h>

#include <string>

namespace gi {

/// 16 lowercase hex digits (gi::ContentHash) over, for every Static instance, in order: its
/// id, its world matrix, and per primitive its triangles as corners (the position and, when
/// present, the normal of each index, in index order; an out-of-range index is hashed as
/// its value) and the factors of the material it renders with (override, own or default:
/// base colour, metallic, roughness, specular, specular colour, emission) and, for a
/// textured or cut-out (Mask, Blend) material only, the textures the bakers read (each
/// image's texels by their XXH3, UV set, wrap, mipmaps, transform), alpha mode, cutoff and
/// alpha factor and the primitive's UV sets per corner: a bundle baked with other textures
/// is stale. An untextured opaque material adds nothing more, so bundles of untextured
/// scenes keep their hash. Dynamic instances, lights, names and the file path do not enter. Vertex order and splitting
/// do not matter as long as the triangles stay the same, so a scene given its atlas uv1 (gi::with_atlas_uv1) hashes
/// like the original.
std::string scene_geometry_hash(const BakeInput& input);

/// 16 hex digits over the lights a static bake (the light atlas) depends on: for every
/// light that does not move, in order, its place among them, its world matrix and its type,
/// colour, intensity, range, cone angles and area size (and a directional light's disc when
/// it has one), then the sky when there is one (uniform and gradient). Moving lights and
/// names do not enter. A light-atlas bundle whose lights hash differs from the scene's was baked under
/// other lights.
std::string static_lights_hash(const BakeInput& input);

}  // namespace gi
