#pragma once
// The fingerprint of what a bake depends on, stored in the bundle's manifest so a bundle
// baked from other geometry or materials is reported as stale instead of silently used.
//   if (manifest.geometry_hash != gi::scene_geometry_hash(asset)) { /* stale bundle */ }

#include <engine/scene_asset.h>

#include <string>

namespace gi {

/// 16 lowercase hex digits (FNV-1a 64, gi::ContentHash) over, for every node with a mesh
/// whose mobility is not Dynamic, in node order: the node index, its world matrix
/// (gi::node_world_matrix), and per primitive its triangles as corners (the position and,
/// when present, the normal of each index, in index order; an out-of-range index is hashed
/// as its value) and its material's base colour, metallic, roughness, emissive and base
/// colour texture pixels (-1 and out-of-range materials hash as the default material).
/// Dynamic nodes, lights, cameras, names and the file path do not enter. Vertex order and
/// splitting do not matter as long as the triangles stay the same, so a scene saved with
/// its atlas uv1 (gi::with_atlas_uv1) hashes like the original.
std::string scene_geometry_hash(const engine::SceneAsset& scene);

/// 16 hex digits over the lights a static bake (the light atlas) depends on: for every node
/// with an enabled light that does not move, in node order, the node index, its world
/// matrix and the light's type, colour, intensity, range, cone angles and area size. Moving
/// or switched-off lights and names do not enter. A light-atlas bundle whose lights hash
/// differs from the scene's was baked under other lights.
std::string static_lights_hash(const engine::SceneAsset& scene);

}  // namespace gi
