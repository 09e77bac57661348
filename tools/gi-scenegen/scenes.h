#pragma once
// The project's generated scenes. Each function builds one scene deterministically;
// write_all_scenes() writes every one of them into a folder.
//   for (const scenegen::GeneratedScene& s : scenegen::all_scenes()) std::cout << s.file_name;
//   engine::Status st = scenegen::write_all_scenes("assets");

#include <filesystem>
#include <string>
#include <vector>

#include <engine/gltf.h>
#include <engine/scene_asset.h>

namespace scenegen {

/// One output file: its name inside the output folder, the scene and how it is written.
struct GeneratedScene {
  std::string file_name;
  std::string purpose;  ///< One line for assets/README.md and --list.
  engine::SceneAsset asset;
  engine::GltfWriteOptions options;
};

engine::SceneAsset cornell_box();
engine::SceneAsset corridor();
engine::SceneAsset spot_chamber();
engine::SceneAsset crates_room();
engine::SceneAsset glossy_room();
engine::SceneAsset demo_level();

/// Every scene of the project, in a fixed order.
std::vector<GeneratedScene> all_scenes();

/// Writes all_scenes() into `dir` (created when missing).
engine::Status write_all_scenes(const std::filesystem::path& dir);

/// Geometry facts of the corridor scene, shared with its tests.
namespace corridor_layout {
inline constexpr float kRoomSize = 6.0f;             ///< Room interior x, z in [0, 6].
inline constexpr float kWall = 0.2f;                 ///< Wall thickness between room and annex.
inline constexpr float kHeight = 3.0f;               ///< Ceiling height of room and corridor.
inline constexpr float kAnnexX = kRoomSize + kWall;  ///< Alcove and corridor start at x = 6.2.
}  // namespace corridor_layout

}  // namespace scenegen
