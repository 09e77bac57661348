#include "render/uniform_lookup.h"

#include <algorithm>
#include <cctype>

#include <GL/glcorearb.h>
#include <engine/check.h>

namespace engine {

namespace {

bool identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

std::string_view skip_space(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
  return s;
}

// The identifier at the start of `s` (empty if none), and `s` advanced past it.
std::string_view take_identifier(std::string_view& s) {
  s = skip_space(s);
  std::size_t n = 0;
  while (n < s.size() && identifier_char(s[n])) ++n;
  const std::string_view id = s.substr(0, n);
  s.remove_prefix(n);
  return id;
}

bool precision_qualifier(std::string_view word) { return word == "highp" || word == "mediump" || word == "lowp"; }

}  // namespace

std::set<std::string> declared_uniforms(std::string_view source) {
  std::set<std::string> names;
  while (!source.empty()) {
    const std::size_t nl = source.find('\n');
    std::string_view line = source.substr(0, nl);
    source = nl == std::string_view::npos ? std::string_view{} : source.substr(nl + 1);
    if (const std::size_t comment = line.find("//"); comment != std::string_view::npos) line = line.substr(0, comment);
    for (std::size_t at = line.find("uniform"); at != std::string_view::npos; at = line.find("uniform", at + 1)) {
      const bool starts_word = at == 0 || !identifier_char(line[at - 1]);
      const bool ends_word = at + 7 >= line.size() || !identifier_char(line[at + 7]);
      if (!starts_word || !ends_word) continue;
      std::string_view rest = line.substr(at + 7);
      std::string_view type = take_identifier(rest);
      while (precision_qualifier(type)) type = take_identifier(rest);
      if (type.empty()) continue;
      for (;;) {  // one or more names: `uniform vec3 a, b[2];`
        const std::string_view name = take_identifier(rest);
        if (name.empty()) break;  // a block (`uniform Block {`) or a declaration split over lines
        names.emplace(name);
        rest = skip_space(rest);
        if (!rest.empty() && rest.front() == '[') rest = rest.substr(std::min(rest.size(), rest.find(']') + 1));
        rest = skip_space(rest);
        if (rest.empty() || rest.front() != ',') break;
        rest.remove_prefix(1);
      }
      break;
    }
  }
  return names;
}

UniformLookup::UniformLookup(const ShaderProgram& program, const ShaderProgramBuilder& builder,
                             const std::vector<std::string_view>& stage_files)
    : program_(program) {
  for (std::string_view file : stage_files) {
    stages_ += (stages_.empty() ? "" : " + ") + std::string(file);
    const Result<std::string> source = builder.preprocess(file);
    GI_EXPECTS(source.ok(), "UniformLookup's stage files are the ones the builder built");
    declared_.merge(declared_uniforms(source.value()));
  }
}

int UniformLookup::location(std::string_view name) const {
  if (!declares(name)) {
    const std::string message =
        "C++ sets uniform '" + std::string(name) + "', which no stage of " + stages_ + " declares";
    GI_EXPECTS(declares(name), message.c_str());
  }
  return glGetUniformLocation(program_.id(), std::string(name).c_str());
}

}  // namespace engine
