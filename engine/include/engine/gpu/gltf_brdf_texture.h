#pragma once
// The GPU copy of engine::gltf_albedo_table() (engine/gltf_brdf.h) that gltf_brdf.glsl's
// gltf_directional_albedo() reads: a 32 x 32 RGBA32F texture, node (i, j) at texel (i, j).
// Bind it at GLTF_ALBEDO_TABLE_BINDING (8 unless the shader defines otherwise).
//   engine::GlTexture table = engine::upload_gltf_albedo_table();   // GL context current
//   glBindTextureUnit(8, table.id());

#include <engine/gpu/gl_objects.h>

namespace engine {

/// Texture unit gltf_brdf.glsl reads the table from by default.
inline constexpr unsigned kGltfAlbedoTableUnit = 8;

/// Uploads the table (computing it on first use). Needs a current GL context.
GlTexture upload_gltf_albedo_table();

}  // namespace engine
