#pragma once
// The light-atlas parameterisation (TEXCOORD_1) of a scene's static world, as the light
// atlas, the PRM, the directional light maps and the renderer use it, for artists and other
// tools to inspect or reuse the lightmap UVs (gi-bake --export-uv1 OUT.gltf).
//   auto scene = engine::load_gltf("level.gltf").value();
//   auto uv = gi::with_light_atlas_uv1(scene, {.preset = "medium"});
//   if (uv) engine::write_gltf(uv->scene, "level_uv1.gltf");
//
// The layout is the one gi::bake_bundle builds for the same preset (or texels_per_metre)
// and GISystem::load applies: deterministic, so loading the written file gives the static
// meshes exactly the uv1 a bundle baked from the original scene gives them. Vertices on
// chart borders are split and a mesh shared by several static nodes is duplicated per node
// ("<mesh>@<node>"); dynamic nodes keep their meshes untouched (gi/src/uv/atlas_scene_writer.h).

#include <engine/result.h>
#include <engine/scene_asset.h>

#include <cstddef>
#include <string>

namespace gi {

struct LightAtlasUvOptions {
  std::string preset = "medium";  ///< preview | medium | high: the preset's atlas density.
  float texels_per_metre = 0.0f;  ///< Overrides the preset's density when positive (gi-bake --density).
};

struct LightAtlasUv {
  engine::SceneAsset scene;       ///< The input with TEXCOORD_1 on every static mesh.
  int width = 0;                  ///< Atlas texels.
  int height = 0;                 ///< Atlas texels.
  float texels_per_metre = 0.0f;  ///< Achieved density (below the request when the charts did not fit).
  std::size_t charts = 0;
};

/// Errors: an unknown preset, a density out of range, a static world that cannot be laid
/// out (no static triangles, degenerate input), each with a message naming the problem.
engine::Result<LightAtlasUv> with_light_atlas_uv1(const engine::SceneAsset& scene,
                                                  const LightAtlasUvOptions& options = {});

}  // namespace gi
