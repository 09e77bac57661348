#pragma once
// Shader sources embedded at build time (cmake/GiEmbedShaders.cmake).

#include <span>
#include <string_view>

namespace engine {

/// One embedded GLSL file: its file name, the path it was embedded from (for messages) and
/// its text. `#include "x_common.glsl"` lines are resolved against the same table.
struct ShaderFile {
  std::string_view name;
  std::string_view path;
  std::string_view text;
};

/// The engine's own shaders (engine/shaders/*.glsl).
std::span<const ShaderFile> engine_shader_files();

}  // namespace engine
