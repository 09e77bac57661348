// The architecture, checked: gi/src folders include only the folders of the targets they
// link (gi/CMakeLists.txt writes the targets' folders and links to GI_LAYERS_FILE), the
// folder include graph has no cycle, engine never includes gi, and nothing outside gi/
// includes gi/src: tools, the demo and the top-level tests use the public headers; the
// methods read their bundle files through the one reader path (bundle/bundle_reader.h); and no
// engine or gi code sets a uniform by a literal location (CONVENTIONS.md 16: blocks or named,
// cached locations).
#include <gtest/gtest.h>
#include <gi/methods.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Layers {
  std::map<std::string, std::string> target_of_folder;
  std::map<std::string, std::set<std::string>> links;  // target -> targets it links
};

Layers read_layers() {
  Layers l;
  std::ifstream in(GI_LAYERS_FILE);
  EXPECT_TRUE(in) << "cannot read " << GI_LAYERS_FILE;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string kind, target;
    words >> kind >> target;
    if (kind == "folder") {
      std::string folder;
      words >> folder;
      l.target_of_folder[folder] = target;
    } else if (kind == "link") {
      for (std::string t; words >> t;) l.links[target].insert(t);
    }
  }
  return l;
}

bool is_source(const fs::path& p) {
  const std::string e = p.extension().string();
  return e == ".h" || e == ".cpp" || e == ".hpp";
}

// "folder/..." of every #include "folder/file.h" in `file`.
std::set<std::string> included_folders(const fs::path& file) {
  static const std::regex include_re(R"re(^\s*#\s*include\s*"([a-z_0-9]+)/[^"]+")re");
  std::set<std::string> out;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, include_re)) out.insert(m[1]);
  }
  return out;
}

std::set<std::string> reachable_targets(const Layers& l, const std::string& target) {
  std::set<std::string> seen{target};
  std::vector<std::string> todo{target};
  while (!todo.empty()) {
    const std::string t = todo.back();
    todo.pop_back();
    auto it = l.links.find(t);
    if (it == l.links.end()) continue;
    for (const std::string& next : it->second)
      if (seen.insert(next).second) todo.push_back(next);
  }
  return seen;
}

const fs::path kGiSrc = fs::path(GI_SOURCE_DIR) / "gi" / "src";

// folder -> folders its files include (other gi/src folders only).
std::map<std::string, std::set<std::string>> folder_graph(const Layers& l) {
  std::map<std::string, std::set<std::string>> g;
  for (const auto& [folder, target] : l.target_of_folder) {
    g[folder];
    if (!fs::exists(kGiSrc / folder)) continue;
    for (const auto& e : fs::recursive_directory_iterator(kGiSrc / folder))
      if (e.is_regular_file() && is_source(e.path()))
        for (const std::string& inc : included_folders(e.path()))
          if (inc != folder && l.target_of_folder.count(inc)) g[folder].insert(inc);
  }
  return g;
}

TEST(Architecture, EveryGiSrcFolderBelongsToATarget) {
  const Layers l = read_layers();
  for (const auto& e : fs::directory_iterator(kGiSrc)) {
    if (!e.is_directory()) continue;
    EXPECT_TRUE(l.target_of_folder.count(e.path().filename().string()))
        << "gi/src/" << e.path().filename().string() << " is compiled by no target in gi/CMakeLists.txt";
  }
}

TEST(Architecture, FoldersIncludeOnlyFoldersOfTheTargetsTheyLink) {
  const Layers l = read_layers();
  ASSERT_FALSE(l.target_of_folder.empty());
  for (const auto& [folder, includes] : folder_graph(l)) {
    const std::string& target = l.target_of_folder.at(folder);
    const std::set<std::string> allowed = reachable_targets(l, target);
    for (const std::string& inc : includes)
      EXPECT_TRUE(allowed.count(l.target_of_folder.at(inc)))
          << "gi/src/" << folder << " (" << target << ") includes gi/src/" << inc << " (" << l.target_of_folder.at(inc)
          << "), a target it does not link";
  }
}

TEST(Architecture, FolderIncludeGraphHasNoCycle) {
  const Layers l = read_layers();
  const auto g = folder_graph(l);
  // Depth-first search with colours; a grey node reached again closes a cycle.
  std::map<std::string, int> colour;
  std::vector<std::string> path;
  std::string cycle;
  std::function<void(const std::string&)> visit = [&](const std::string& f) {
    colour[f] = 1;
    path.push_back(f);
    for (const std::string& next : g.at(f)) {
      if (!cycle.empty()) break;
      if (colour[next] == 1) {
        for (auto it = std::find(path.begin(), path.end(), next); it != path.end(); ++it) cycle += *it + " -> ";
        cycle += next;
      } else if (colour[next] == 0) {
        visit(next);
      }
    }
    path.pop_back();
    colour[f] = 2;
  };
  for (const auto& [f, unused] : g)
    if (colour[f] == 0 && cycle.empty()) visit(f);
  EXPECT_TRUE(cycle.empty()) << "include cycle between gi/src folders: " << cycle;
}

TEST(Architecture, NothingOutsideGiIncludesGiSrcAndEngineNeverIncludesGi) {
  const Layers l = read_layers();
  static const std::regex gi_public(R"re(^\s*#\s*include\s*[<"]gi/)re");
  for (const char* top : {"engine", "tools", "tests", "game_demo"}) {
    for (const auto& e : fs::recursive_directory_iterator(fs::path(GI_SOURCE_DIR) / top)) {
      if (!e.is_regular_file()) continue;
      const std::string rel = fs::relative(e.path(), GI_SOURCE_DIR).string();
      if (e.path().filename() == "CMakeLists.txt") {
        std::ifstream in(e.path());
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_EQ(text.find("gi/src"), std::string::npos) << rel << " puts gi/src on an include path";
        continue;
      }
      if (!is_source(e.path())) continue;
      for (const std::string& inc : included_folders(e.path()))
        EXPECT_FALSE(l.target_of_folder.count(inc)) << rel << " includes gi/src/" << inc << "/...";
      if (std::string(top) == "engine") {
        std::ifstream in(e.path());
        for (std::string line; std::getline(in, line);)
          EXPECT_FALSE(std::regex_search(line, gi_public)) << rel << " (engine) includes gi: " << line;
      }
    }
  }
}

// GISystem composes the methods through the method table only (gi/src/system/method_table.h,
// issue 34): gi_system.cpp includes no method's folder and no method's adapter, and every
// method of gi/methods.h has its adapter, system/<key>_method.cpp, whose loader the table
// names. A sixth method is its adapter file and one row; GISystem does not change.
TEST(Architecture, GiSystemKnowsNoMethodOnlyTheTable) {
  const fs::path system = kGiSrc / "system" / "gi_system.cpp";
  const std::set<std::string> folders = included_folders(system);
  for (const gi::MethodDescriptor& m : gi::kMethods)
    EXPECT_FALSE(folders.count(std::string(m.key))) << "gi_system.cpp includes gi/src/" << m.key << "/...";
  for (const char* f : {"prm", "brf", "dlm"}) EXPECT_FALSE(folders.count(f)) << "gi_system.cpp includes gi/src/" << f;
  static const std::regex adapter(R"re(^\s*#\s*include\s*"system/[a-z_0-9]+_(lighting|method|probe_light)\.h")re");
  std::ifstream in(system);
  for (std::string line; std::getline(in, line);)
    EXPECT_FALSE(std::regex_search(line, adapter)) << "gi_system.cpp includes a method's adapter: " << line;
  std::ifstream table_in(kGiSrc / "system" / "method_table.cpp");
  const std::string table((std::istreambuf_iterator<char>(table_in)), std::istreambuf_iterator<char>());
  for (const gi::MethodDescriptor& m : gi::kMethods) {
    const std::string key(m.key);
    EXPECT_TRUE(fs::exists(kGiSrc / "system" / (key + "_method.cpp"))) << "no adapter system/" << key << "_method.cpp";
    EXPECT_NE(table.find("&load_" + key + "_method"), std::string::npos)
        << "method_table.cpp does not name load_" << key << "_method";
  }
}

// The bake's twin of the rule above (issue 34): bake_bundle.cpp includes no method's folder
// and names no baker; every method of gi/methods.h has its baker, bake/<key>_baker.cpp, and
// its row in bake/method_bakers.cpp. A sixth method bakes through its baker file and a row.
TEST(Architecture, BakeBundleKnowsNoMethodOnlyTheBakerTable) {
  const fs::path bundle = kGiSrc / "bake" / "bake_bundle.cpp";
  const std::set<std::string> folders = included_folders(bundle);
  for (const gi::MethodDescriptor& m : gi::kMethods)
    EXPECT_FALSE(folders.count(std::string(m.key))) << "bake_bundle.cpp includes gi/src/" << m.key << "/...";
  for (const char* f : {"prm", "brf", "dlm", "light_atlas", "antiradiance"})
    EXPECT_FALSE(folders.count(f)) << "bake_bundle.cpp includes gi/src/" << f;
  std::ifstream bundle_in(bundle);
  const std::string bundle_text((std::istreambuf_iterator<char>(bundle_in)), std::istreambuf_iterator<char>());
  std::ifstream table_in(kGiSrc / "bake" / "method_bakers.cpp");
  const std::string table((std::istreambuf_iterator<char>(table_in)), std::istreambuf_iterator<char>());
  for (const gi::MethodDescriptor& m : gi::kMethods) {
    const std::string key(m.key);
    EXPECT_TRUE(fs::exists(kGiSrc / "bake" / (key + "_baker.cpp"))) << "no baker bake/" << key << "_baker.cpp";
    EXPECT_NE(table.find("&bake_" + key + "_method"), std::string::npos)
        << "method_bakers.cpp does not name bake_" << key << "_method";
    EXPECT_EQ(bundle_text.find("bake_" + key + "_method"), std::string::npos)
        << "bake_bundle.cpp calls bake_" << key << "_method itself, not through the table";
  }
}

// Where `text` calls glUniform* / glProgramUniform* with a literal integer location (the
// first argument, or the second after glProgramUniform's program), as "line N: call".
// Calls may span lines: the location can sit on the line after the '('.
std::vector<std::string> literal_uniform_locations(const std::string& text) {
  static const std::regex call_re(R"re(\bgl(Program)?Uniform\w*\s*\()re");
  static const std::regex literal_re(R"re(^\s*[0-9][0-9a-fA-FxXuU]*\s*$)re");
  std::vector<std::string> found;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), call_re); it != std::sregex_iterator(); ++it) {
    const std::size_t open = static_cast<std::size_t>(it->position() + it->length());
    // The arguments up to the location's ',' or ')' at depth 0.
    std::vector<std::string> args(1);
    int depth = 0;
    for (std::size_t i = open; i < text.size() && args.size() <= 2; ++i) {
      const char c = text[i];
      if (c == '(') ++depth;
      if (c == ')' && depth-- == 0) break;
      if (c == ',' && depth == 0) {
        args.emplace_back();
        continue;
      }
      args.back() += c;
    }
    const std::size_t location_arg = (*it)[1].matched ? 1 : 0;
    if (args.size() <= location_arg || !std::regex_match(args[location_arg], literal_re)) continue;
    const auto line = 1 + std::count(text.begin(), text.begin() + it->position(), '\n');
    found.push_back("line " + std::to_string(line) + ": " + it->str() + args[0] +
                    (location_arg == 1 ? "," + args[1] : std::string()) + ", ...");
  }
  return found;
}

TEST(Architecture, LiteralUniformLocationCheckCatchesTheOldPatterns) {
  // The forms engine/src used before named locations (forward_renderer.cpp, exposure_meter.cpp).
  EXPECT_EQ(literal_uniform_locations("glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(view_proj));").size(), 1u);
  EXPECT_EQ(literal_uniform_locations("  glUniform1i(\n            66, (baked ? 1 : 0) | 2);").size(), 1u);
  EXPECT_EQ(literal_uniform_locations("glUniform2f(2, low, std::clamp(h, low, 1.0f));\nglUniform1f( 4 , c);").size(),
            2u);
  EXPECT_EQ(literal_uniform_locations("glProgramUniform1ui(program.id(), 3, items);").size(), 1u);
  EXPECT_EQ(literal_uniform_locations("glProgramUniform1ui(id(f(1, 2)), 0x10u, items);").size(), 1u);
  // What it must let through: named locations, looked-up ones, literal values.
  EXPECT_TRUE(literal_uniform_locations("glUniform1i(u.lobe_terms, 0);").empty());
  EXPECT_TRUE(literal_uniform_locations("glUniformMatrix4fv(at(\"u_model\"), 1, GL_FALSE, m);").empty());
  EXPECT_TRUE(
      literal_uniform_locations("glProgramUniform1ui(p.id(), glGetUniformLocation(p.id(), \"u_bins\"), 8);").empty());
  EXPECT_TRUE(literal_uniform_locations("glUniformBlockBinding(program, 0, 1);").empty());
}

TEST(Architecture, NoUniformIsSetByALiteralLocation) {
  std::size_t files = 0;
  for (const char* top : {"engine", "gi"}) {
    for (const auto& e : fs::recursive_directory_iterator(fs::path(GI_SOURCE_DIR) / top)) {
      if (!e.is_regular_file() || !is_source(e.path())) continue;
      ++files;
      std::ifstream in(e.path());
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      for (const std::string& call : literal_uniform_locations(text))
        ADD_FAILURE() << fs::relative(e.path(), GI_SOURCE_DIR).string() << " " << call
                      << ": a literal uniform location; use a uniform block or a location looked up by name once "
                         "per link (engine/src/render/program_uniforms.h)";
    }
  }
  EXPECT_GT(files, 100u) << "the scan found almost no sources under engine/ and gi/";
}

}  // namespace

// One reader path: a method (a target that links gi_transport: gi_light_atlas, gi_prm, ...)
// never reads manifest.json or checks a bundle file's checksum itself. It opens its entry
// through gi::BundleReader (gi/src/bundle/bundle_reader.h), which makes the manifest,
// geometry, file-name and checksum checks once, with one error text for every method. The
// rule: no source in a method's folder calls read_manifest, read_current_manifest,
// manifest_method or check_file_checksum (writers may still call update_manifest_method).
TEST(Architecture, MethodsReadTheirBundleFilesThroughTheBundleReader) {
  const Layers l = read_layers();
  std::set<std::string> method_targets;
  for (const auto& [target, linked] : l.links)
    if (linked.count("gi_transport")) method_targets.insert(target);
  ASSERT_GE(method_targets.size(), 5u) << "the layers file lists fewer method targets than the five methods";
  static const std::regex bundle_access(
      R"re(\b(read_manifest|read_current_manifest|manifest_method|check_file_checksum)\s*\()re");
  std::size_t files_checked = 0;
  for (const auto& [folder, target] : l.target_of_folder) {
    if (!method_targets.count(target) || !fs::exists(kGiSrc / folder)) continue;
    for (const auto& e : fs::recursive_directory_iterator(kGiSrc / folder)) {
      if (!e.is_regular_file() || !is_source(e.path())) continue;
      ++files_checked;
      std::ifstream in(e.path());
      int line_number = 0;
      for (std::string line; std::getline(in, line);) {
        ++line_number;
        const std::string code = line.substr(0, line.find("//"));
        std::smatch m;
        EXPECT_FALSE(std::regex_search(code, m, bundle_access))
            << "gi/src/" << folder << "/" << e.path().filename().string() << ":" << line_number << " calls " << m[1]
            << ": a method reads its bundle entry through gi::BundleReader (bundle/bundle_reader.h)";
      }
    }
  }
  EXPECT_GT(files_checked, 0u);
}
