// gi-scenegen: writes the project's generated scenes (assets/) deterministically.
//   gi-scenegen --out assets          # regenerate every scene
//   gi-scenegen --list                # name, triangles and purpose of each scene
#include <cstdio>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "scenes.h"

namespace {
std::size_t triangle_count(const engine::SceneAsset& asset) {
  std::size_t n = 0;
  for (const engine::Node& node : asset.nodes) {
    if (node.mesh < 0) continue;
    for (const engine::Primitive& p : asset.meshes[static_cast<std::size_t>(node.mesh)].primitives)
      n += (p.indices.empty() ? p.positions.size() : p.indices.size()) / 3;
  }
  return n;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes the project's generated glTF scenes"};
  std::string out_dir;
  bool list = false;
  app.add_option("--out", out_dir, "Output folder (created when missing), e.g. assets");
  app.add_flag("--list", list, "List the scenes (file, drawn triangles, purpose) and exit");
  CLI11_PARSE(app, argc, argv);

  if (list) {
    for (const scenegen::GeneratedScene& s : scenegen::all_scenes())
      std::printf("%-24s %6zu triangles  %s\n", s.file_name.c_str(), triangle_count(s.asset), s.purpose.c_str());
    return 0;
  }
  if (out_dir.empty()) {
    std::cerr << "gi-scenegen: give --out DIR (or --list)\n";
    return 2;
  }
  if (auto st = scenegen::write_all_scenes(out_dir); !st) {
    std::cerr << "gi-scenegen: " << st.error().to_string() << '\n';
    return 1;
  }
  return 0;
}
