#pragma once
// An atlas layout as TEXCOORD_1 (Primitive::uv1) of the static meshes: written into a copy
// of scene data, so the light atlas parameterization can be saved with engine::write_gltf,
// or handed to the renderer as atlas meshes (engine/indirect_light.h) beside a scene that
// stays as the game made it.
//   auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(asset));
//   engine::Result<engine::SceneAsset> with_uv1 = gi::with_atlas_uv1(asset, layout.value());
//   auto meshes = gi::atlas_meshes_of(scene, layout.value());   // scene unchanged

#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>

#include <vector>
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

/// For a scene already instantiated, without changing it: per static mesh instance of the
/// layout whose node has a live entity, that entity's mesh with the layout's uv1 (vertices
/// split as above), to draw in place of the scene's mesh (engine::IndirectLightProvider::
/// atlas_meshes). Each instance gets its own mesh, whether or not its mesh is shared.
/// Error when the layout does not match the scene, as with_atlas_uv1.
engine::Result<std::vector<engine::AtlasMesh>> atlas_meshes_of(const engine::Scene& scene, const AtlasLayout& layout);

}  // namespace gi
