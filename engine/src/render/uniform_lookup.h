#pragma once
// Uniform locations by name, looked up once after a program links, so C++ never addresses a
// uniform by a number the GLSL could change under it. A name the program's sources do not
// declare is a programmer error (C++ and GLSL out of step) and aborts naming both; a declared
// uniform the driver compiled out of this variant gets -1, which glUniform* ignores.
//   const UniformLookup at(program, builder);        // the builder that built `program`
//   const GLint view_proj = at.location("u_view_proj");

#include <initializer_list>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <engine/gpu/shader_program.h>

namespace engine {

class UniformLookup {
 public:
  /// Reads the declared uniforms of `stage_files` as `builder` preprocesses them (includes
  /// and #defines resolved; #if blocks are not evaluated, so a name is declared if any
  /// branch declares it). `program` must be what `builder` built from those stages.
  UniformLookup(const ShaderProgram& program, const ShaderProgramBuilder& builder,
                const std::vector<std::string_view>& stage_files);

  /// glGetUniformLocation of `name` (-1: declared but inactive in this variant).
  /// Precondition: a stage declares `name`.
  int location(std::string_view name) const;
  /// True when a stage declares a uniform called `name`.
  bool declares(std::string_view name) const { return declared_.count(std::string(name)) > 0; }

 private:
  const ShaderProgram& program_;
  std::string stages_;  // "a.vert.glsl + b.frag.glsl", for messages
  std::set<std::string> declared_;
};

/// The names `uniform <type> <name>` declares in GLSL `source` (line comments ignored;
/// uniform blocks, whose name is followed by '{', are not included).
std::set<std::string> declared_uniforms(std::string_view source);

}  // namespace engine
