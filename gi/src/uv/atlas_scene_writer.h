#pragma once
// Writes an atlas layout back into scene data as TEXCOORD_1 (Primitive::uv1), so the light
// atlas parameterization can be saved with engine::write_gltf and read by the renderer.
//   auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(asset));
//   engine::Result<engine::SceneAsset> with_uv1 = gi::with_atlas_uv1(asset, layout.value());

#include <engine/result.h>
#include <engine/scene.h>
#include <engine/scene_asset.h>

#include "uv/atlas_layout.h"

namespace gi {

/// A copy of `scene` whose static mesh instances carry the layout's uv1. The layout must have
/// been built from atlas_inputs_from(scene) (its mesh ids are node indices).
/// - Vertices the layout split are split in the primitive that owns them: a primitive keeps
///   its vertices in order and gets its split copies appended (in the layout's order); all
///   attributes are copied from the source vertex and indices are rewritten.
/// - Each static instance needs its own atlas region, so a mesh used by several nodes is
///   duplicated: the first static node using it takes the mesh in place unless a dynamic
///   node also uses it; every other static node gets a copy appended to `meshes`, named
///   "<mesh name>@<node name>".
/// - Dynamic nodes and their meshes are left alone.
/// Error when the layout does not match the scene (ids, vertex or triangle counts).
engine::Result<engine::SceneAsset> with_atlas_uv1(const engine::SceneAsset& scene, const AtlasLayout& layout);

/// The same for a scene already instantiated: replaces `scene.assets` with its uv1 copy and
/// points the MeshRenderer of every node whose mesh was duplicated at its copy. On error
/// the scene is unchanged.
engine::Status apply_atlas_uv1(engine::Scene& scene, const AtlasLayout& layout);

}  // namespace gi
