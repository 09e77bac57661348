#pragma once
// gi's own shaders (gi/shaders/*.glsl), embedded at build time by gi_embed_shaders
// (cmake/GiEmbedShaders.cmake).
//   auto p = engine::ShaderProgramBuilder(gi::gi_shader_files())
//                .stage(engine::ShaderStage::Compute, "prm_sum.comp.glsl").build();

#include <span>

#include <engine/shader_source.h>

namespace gi {

/// Every gi/shaders/*.glsl file: name, source path and text (static storage).
std::span<const engine::ShaderFile> gi_shader_files();

}  // namespace gi
