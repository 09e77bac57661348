#pragma once
// GLSL programs built from embedded shader files (engine/shader_source.h). `#include
// "x_common.glsl"` lines are resolved from the same tables (each file included once per
// stage); `#line` directives keep driver messages mappable, so a compile error is reported
// as an engine::Error {file = "path/of/the/included.glsl", location = "line 12", ...} whose
// to_string() reads "path: line 12: message".
//   auto p = engine::ShaderProgramBuilder(engine::engine_shader_files())
//                .stage(engine::ShaderStage::Vertex, "forward.vert.glsl").stage(engine::ShaderStage::Fragment,
//                "forward.frag.glsl").build();

#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <engine/gpu/gl_objects.h>
#include <engine/result.h>
#include <engine/shader_source.h>

namespace engine {

enum class ShaderStage : std::uint8_t { Vertex, Geometry, Fragment, Compute };

/// A linked GL program (move-only; the moved-from program is empty).
class ShaderProgram {
 public:
  ShaderProgram() = default;
  explicit ShaderProgram(GlProgram program) : program_(std::move(program)) {}
  std::uint32_t id() const { return program_.id(); }
  bool empty() const { return program_.empty(); }
  /// glUseProgram(id()).
  void use() const;

 private:
  GlProgram program_;
};

/// Collects stages and `#define`s and builds a ShaderProgram; errors name the file and
/// line of the (possibly included) source that failed.
class ShaderProgramBuilder {
 public:
  explicit ShaderProgramBuilder(std::span<const ShaderFile> files);
  /// More files to resolve names and includes from (e.g. engine commons used by gi shaders).
  ShaderProgramBuilder& add_files(std::span<const ShaderFile> files);
  /// Adds a stage whose main file is `file_name` (a ShaderFile::name).
  ShaderProgramBuilder& stage(ShaderStage stage, std::string_view file_name);
  /// Adds "#define <text>" after the #version line of every stage, e.g. define("MAX_LIGHTS 16").
  ShaderProgramBuilder& define(std::string text);
  Result<ShaderProgram> build() const;

  /// The preprocessed source of one file as the driver sees it (for tests and debugging).
  Result<std::string> preprocess(std::string_view file_name) const;

 private:
  std::vector<ShaderFile> files_;
  std::vector<std::pair<ShaderStage, std::string>> stages_;
  std::vector<std::string> defines_;
};

}  // namespace engine
