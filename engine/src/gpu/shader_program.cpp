#include <engine/gpu/shader_program.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <sstream>

#include <GL/glcorearb.h>

namespace engine {

namespace {

GLenum gl_stage(ShaderStage s) {
  switch (s) {
    case ShaderStage::Vertex:
      return GL_VERTEX_SHADER;
    case ShaderStage::Geometry:
      return GL_GEOMETRY_SHADER;
    case ShaderStage::Fragment:
      return GL_FRAGMENT_SHADER;
    case ShaderStage::Compute:
      return GL_COMPUTE_SHADER;
  }
  return GL_VERTEX_SHADER;
}

std::string_view trim_left(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return s;
}

// `#include "name"` -> name; otherwise empty.
std::string_view include_target(std::string_view line) {
  line = trim_left(line);
  if (!line.starts_with("#")) return {};
  line = trim_left(line.substr(1));
  if (!line.starts_with("include")) return {};
  line = trim_left(line.substr(7));
  if (line.size() < 2 || line.front() != '"') return {};
  const std::size_t close = line.find('"', 1);
  if (close == std::string_view::npos) return {};
  return line.substr(1, close - 1);
}

bool is_version_line(std::string_view line) {
  line = trim_left(line);
  if (!line.starts_with("#")) return false;
  return trim_left(line.substr(1)).starts_with("version");
}

// Mesa does not always report the source-string number of `#line N S` (identifier errors
// come back as source 0), so the file index is also encoded in the line number itself:
// driver line = file_index * kLinesPerFile + line.
constexpr int kLinesPerFile = 100000;

std::string line_directive(int line, int file_index) {
  return "#line " + std::to_string(file_index * kLinesPerFile + line) + " " + std::to_string(file_index) + "\n";
}

struct Preprocessor {
  const std::vector<ShaderFile>& files;
  std::vector<bool> included;
  std::string out;

  int find(std::string_view name) const {
    for (std::size_t i = 0; i < files.size(); ++i)
      if (files[i].name == name) return static_cast<int>(i);
    return -1;
  }

  // Appends file `index`, expanding includes. `first_line` is the 1-based line to start at.
  Status append(int index, int first_line, int depth) {
    const ShaderFile& f = files[static_cast<std::size_t>(index)];
    if (depth > 32) return Error{std::string(f.path), "", "#include nesting deeper than 32"};
    out += line_directive(first_line, index);
    std::string_view text = f.text;
    int line_no = 0;
    while (!text.empty()) {
      const std::size_t nl = text.find('\n');
      const std::string_view line = text.substr(0, nl);
      text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
      ++line_no;
      if (line_no < first_line) continue;
      const std::string_view target = include_target(line);
      if (!target.empty()) {
        const int inc = find(target);
        if (inc < 0)
          return Error{std::string(f.path), "line " + std::to_string(line_no),
                       "#include \"" + std::string(target) + "\": no such embedded shader file"};
        if (!included[static_cast<std::size_t>(inc)]) {
          included[static_cast<std::size_t>(inc)] = true;
          if (Status s = append(inc, 1, depth + 1); !s) return s;
          out += line_directive(line_no + 1, index);
        } else {
          out += "\n";
        }
        continue;
      }
      if (is_version_line(line)) {
        out += "\n";  // only the top-level #version (emitted first) counts
        continue;
      }
      out += line;
      out += '\n';
    }
    return {};
  }
};

// Maps driver messages "S:L(C): error: msg" (Mesa) or "S(L) : error msg" (NVIDIA) back to
// files. Returns the first error as an Error; the full log goes into the message tail.
Error map_log(const std::vector<ShaderFile>& files, std::string_view stage_file, const std::string& log) {
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    const char* p = line.data();
    const char* end = p + line.size();
    int source = 0;
    int line_no = 0;
    auto r1 = std::from_chars(p, end, source);
    if (r1.ec != std::errc{} || r1.ptr == end) continue;
    p = r1.ptr;
    if (*p != ':' && *p != '(') continue;
    ++p;
    auto r2 = std::from_chars(p, end, line_no);
    if (r2.ec != std::errc{}) continue;
    p = r2.ptr;
    // Skip "(col)" or ")" and the ": " before the message.
    while (p != end && *p != ':') ++p;
    if (p != end) ++p;
    std::string_view message(p, static_cast<std::size_t>(end - p));
    source = line_no / kLinesPerFile;
    line_no %= kLinesPerFile;
    message = trim_left(message);
    if (message.find("error") == std::string_view::npos) continue;
    std::string path = source >= 0 && static_cast<std::size_t>(source) < files.size()
                           ? std::string(files[static_cast<std::size_t>(source)].path)
                           : std::string(stage_file);
    if (path.empty() && source >= 0 && static_cast<std::size_t>(source) < files.size())
      path = std::string(files[static_cast<std::size_t>(source)].name);
    return Error{path, "line " + std::to_string(line_no), std::string(message)};
  }
  return Error{std::string(stage_file), "", "shader compilation failed: " + log};
}

}  // namespace

void ShaderProgram::use() const { glUseProgram(id()); }

ShaderProgramBuilder::ShaderProgramBuilder(std::span<const ShaderFile> files) { add_files(files); }

ShaderProgramBuilder& ShaderProgramBuilder::add_files(std::span<const ShaderFile> files) {
  for (const ShaderFile& f : files)
    if (!f.name.empty()) files_.push_back(f);
  return *this;
}

ShaderProgramBuilder& ShaderProgramBuilder::stage(ShaderStage s, std::string_view file_name) {
  stages_.emplace_back(s, std::string(file_name));
  return *this;
}

ShaderProgramBuilder& ShaderProgramBuilder::define(std::string text) {
  defines_.push_back(std::move(text));
  return *this;
}

Result<std::string> ShaderProgramBuilder::preprocess(std::string_view file_name) const {
  Preprocessor pp{files_, std::vector<bool>(files_.size(), false), {}};
  const int index = pp.find(file_name);
  if (index < 0) return Error{std::string(file_name), "", "no such embedded shader file"};
  pp.included[static_cast<std::size_t>(index)] = true;
  // The #version line must come first: take it from the main file (default 450 core).
  std::string_view text = files_[static_cast<std::size_t>(index)].text;
  std::string version = "#version 450 core";
  int body_start = 1;
  int line_no = 0;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    ++line_no;
    if (is_version_line(line)) {
      version = std::string(trim_left(line));
      body_start = line_no + 1;
      break;
    }
    if (!trim_left(line).empty() && !trim_left(line).starts_with("//")) break;
  }
  pp.out = version + "\n";
  for (const std::string& d : defines_) pp.out += "#define " + d + "\n";
  if (Status s = pp.append(index, body_start, 0); !s) return s.error();
  return std::move(pp.out);
}

Result<ShaderProgram> ShaderProgramBuilder::build() const {
  GI_EXPECTS(!stages_.empty(), "a program needs at least one stage");
  std::vector<GlShader> shaders;
  for (const auto& [stage, file] : stages_) {
    Result<std::string> source = preprocess(file);
    if (!source) return source.error();
    GlShader shader(glCreateShader(gl_stage(stage)));
    const char* text = source.value().c_str();
    glShaderSource(shader.id(), 1, &text, nullptr);
    glCompileShader(shader.id());
    GLint ok = 0;
    glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
      GLint length = 0;
      glGetShaderiv(shader.id(), GL_INFO_LOG_LENGTH, &length);
      std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
      glGetShaderInfoLog(shader.id(), length, nullptr, log.data());
      return map_log(files_, file, log);
    }
    shaders.push_back(std::move(shader));
  }
  GlProgram program(glCreateProgram());
  for (const GlShader& s : shaders) glAttachShader(program.id(), s.id());
  glLinkProgram(program.id());
  for (const GlShader& s : shaders) glDetachShader(program.id(), s.id());
  GLint ok = 0;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program.id(), GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program.id(), length, nullptr, log.data());
    std::string names;
    for (const auto& st : stages_) names += (names.empty() ? "" : " + ") + st.second;
    return Error{names, "link", log};
  }
  return ShaderProgram(std::move(program));
}

}  // namespace engine
