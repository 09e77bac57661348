// The list of generated scenes and their output files.
#include "scenes.h"

#include <system_error>

namespace scenegen {

std::vector<GeneratedScene> all_scenes() {
  std::vector<GeneratedScene> s;
  s.push_back({"cornell_box.gltf", "the measured Cornell box (reference comparisons, light atlas)", cornell_box(), {}});
  s.push_back(
      {"corridor.gltf", "room light reaching a corridor only through >= 2 reflections (multi-bounce)", corridor(), {}});
  s.push_back({"spot_chamber.gltf", "closed chamber lit by one spot light", spot_chamber(), {}});
  s.push_back({"crates_room.gltf", "static area light, movable crates (one red), static statue", crates_room(), {}});
  s.push_back({"glossy_room.gltf", "glossy floor (roughness 0.15) under two point lights", glossy_room(), {}});
  s.push_back(
      {"demo_level.gltf", "the playable level: hub, crate room, glossy corridor, swinging lamp", demo_level(), {}});
  engine::GltfWriteOptions draco;
  draco.binary = true;
  draco.draco = true;
  s.push_back({"crates_room.draco.glb", "Draco-compressed twin of crates_room.gltf", crates_room(), draco});
  s.push_back({"demo_level.draco.glb", "Draco-compressed twin of demo_level.gltf", demo_level(), draco});
  return s;
}

engine::Status write_all_scenes(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return engine::Error{dir.string(), "", "cannot create the output folder: " + ec.message()};
  for (const GeneratedScene& scene : all_scenes()) {
    if (auto st = engine::write_gltf(scene.asset, dir / scene.file_name, scene.options); !st) return st;
  }
  return {};
}

}  // namespace scenegen
