// The GI-to-renderer frame data, checked against its GLSL twins: every element struct of
// engine/indirect_light.h whose static_assert says "must match struct X in F.glsl" has, in
// engine/shaders/F.glsl, a struct X with the same members in the same order and of the
// corresponding types. The static_asserts pin the sizes and offsets on the C++ side; this
// test pins the GLSL side to the same fields, so a member added, dropped or reordered on
// either side fails here instead of reading garbage on the GPU.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Member {
  std::string type, name;
  bool operator==(const Member&) const = default;
};

struct Contract {
  std::string cpp_struct, glsl_struct, glsl_file;
  std::vector<Member> members;  // C++ members, types already mapped to GLSL
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in) << "cannot read " << p;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string glsl_type(const std::string& cpp) {
  static const std::map<std::string, std::string> kTypes = {
      {"glm::vec2", "vec2"},     {"glm::vec3", "vec3"},   {"glm::vec4", "vec4"}, {"float", "float"},
      {"std::uint32_t", "uint"}, {"std::int32_t", "int"}, {"int", "int"},        {"glm::uvec2", "uvec2"},
      {"glm::uvec4", "uvec4"},   {"glm::ivec4", "ivec4"}};
  const auto it = kTypes.find(cpp);
  return it == kTypes.end() ? "<no GLSL type for " + cpp + ">" : it->second;
}

// Members of `struct Name { ... };` bodies: "type name{...};", "type name = ...;", "type name;".
std::vector<Member> members_of(const std::string& body, bool map_to_glsl) {
  static const std::regex kMember(R"(^\s*([A-Za-z_][\w:]*)\s+([A-Za-z_]\w*)\s*(?:\{[^;]*\}|=[^;]*)?;)");
  std::vector<Member> out;
  std::istringstream lines(body);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, kMember) && m[1] != "return")
      out.push_back({map_to_glsl ? glsl_type(m[1]) : std::string(m[1]), m[2]});
  }
  return out;
}

// The body of the brace block that opens at `open` (an index of '{'), without its braces.
std::string block_at(const std::string& text, std::size_t open) {
  int depth = 0;
  for (std::size_t i = open; i < text.size(); ++i) {
    if (text[i] == '{') ++depth;
    if (text[i] == '}' && --depth == 0) return text.substr(open + 1, i - open - 1);
  }
  return text.substr(open + 1);
}

// Every "struct S { ... }; static_assert(..., "must match struct X in F.glsl ...")" of a header.
std::vector<Contract> contracts_in(const std::string& header) {
  static const std::regex kHead(R"(struct\s+(\w+)\s*\{)");
  static const std::regex kAssert(R"(^\s*;\s*static_assert\([^;]*?"must match struct (\w+) in ([\w.]+\.glsl))");
  std::vector<Contract> out;
  for (auto it = std::sregex_iterator(header.begin(), header.end(), kHead); it != std::sregex_iterator(); ++it) {
    const std::size_t open = static_cast<std::size_t>(it->position(0) + it->length(0) - 1);
    const std::string body = block_at(header, open);
    const std::string after = header.substr(open + body.size() + 2);
    std::smatch a;
    if (std::regex_search(after, a, kAssert)) out.push_back({(*it)[1], a[1], a[2], members_of(body, true)});
  }
  return out;
}

// The members of `struct name { ... };` in GLSL source (found = false when there is none).
std::vector<Member> glsl_struct(const std::string& source, const std::string& name, bool& found) {
  const std::regex kStruct("struct\\s+" + name + "\\s*\\{");
  std::smatch m;
  found = std::regex_search(source, m, kStruct);
  return found ? members_of(block_at(source, static_cast<std::size_t>(m.position(0) + m.length(0) - 1)), false)
               : std::vector<Member>{};
}

// Empty when the contract holds, else what differs.
std::string check(const Contract& c, const std::string& glsl_source) {
  bool found = false;
  const std::vector<Member> g = glsl_struct(glsl_source, c.glsl_struct, found);
  if (!found) return "no struct " + c.glsl_struct + " in " + c.glsl_file;
  if (g == c.members) return "";
  std::string why = c.cpp_struct + " vs " + c.glsl_struct + ":";
  for (const Member& m : c.members) why += " " + m.type + " " + m.name + ";";
  why += " against";
  for (const Member& m : g) why += " " + m.type + " " + m.name + ";";
  return why;
}

TEST(GpuLayout, TheCheckCatchesAMemberDroppedRenamedOrRetyped) {
  const std::string header = R"hdr(
struct Thing {
  glm::vec3 colour{0.0f};  ///< doc
  float weight = 1.0f;
};
static_assert(sizeof(Thing) == 16, "must match struct ThingElement in thing.glsl (std430)");
)hdr";
  const std::vector<Contract> c = contracts_in(header);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].members, (std::vector<Member>{{"vec3", "colour"}, {"float", "weight"}}));
  EXPECT_EQ(check(c[0], "struct ThingElement {\n  vec3 colour;\n  float weight;\n};"), "");
  EXPECT_NE(check(c[0], "struct ThingElement {\n  vec3 colour;\n};"), "");
  EXPECT_NE(check(c[0], "struct ThingElement {\n  vec3 colour;\n  float mass;\n};"), "");
  EXPECT_NE(check(c[0], "struct ThingElement {\n  vec4 colour;\n  float weight;\n};"), "");
  EXPECT_NE(check(c[0], "struct ThingElement {\n  float weight;\n  vec3 colour;\n};"), "");
  EXPECT_NE(check(c[0], "struct OtherName {\n  vec3 colour;\n  float weight;\n};"), "");
}

TEST(GpuLayout, EveryFrameDataElementMatchesItsGlslStruct) {
  const fs::path root(GI_SOURCE_DIR);
  const std::vector<Contract> contracts = contracts_in(read_text(root / "engine/include/engine/indirect_light.h"));
  // VertexIrradiance, LobeCoefficient, LobeCell, DirectionalRadiance, DirectionalBin.
  EXPECT_GE(contracts.size(), 5u);
  for (const Contract& c : contracts) {
    const fs::path shader = root / "engine" / "shaders" / c.glsl_file;
    ASSERT_TRUE(fs::exists(shader)) << c.cpp_struct << " names " << shader << ", which does not exist";
    EXPECT_EQ(check(c, read_text(shader)), "") << "in " << shader;
  }
}

}  // namespace
