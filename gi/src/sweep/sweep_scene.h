#pragma once
// A scene as the sweep harness sees it: where it came from, its loaded data and a content
// fingerprint that keys the reference cache.
//   auto scene = gi::load_sweep_scene("assets/cornell_box.gltf");
//   if (scene) std::cout << scene->content_hash << '\n';

#include <engine/result.h>
#include <engine/scene_asset.h>

#include <filesystem>
#include <string>

namespace gi {

struct SweepScene {
  std::filesystem::path path;  ///< The scene file; empty for scenes built in memory.
  engine::SceneAsset asset;    ///< What the loader read (meshes, materials, lights, ...).
  std::string content_hash;    ///< scene_fingerprint(path, asset): 16 hex digits.

  /// The name used in CSV rows: the file name, or "<memory>".
  std::string display_name() const { return path.empty() ? std::string("<memory>") : path.filename().string(); }
};

/// Hash of the scene's content: the scene file's bytes (when `path` is not empty) and every
/// field of the loaded asset -- geometry, materials, decoded images, lights, cameras, nodes
/// -- which covers the .bin buffers and images a .gltf references. Any change to what a
/// renderer could see changes it. Errors: the file cannot be read.
engine::Result<std::string> scene_fingerprint(const std::filesystem::path& path, const engine::SceneAsset& asset);

/// Loads a glTF/GLB scene and fingerprints it. Errors: those of engine::load_gltf.
engine::Result<SweepScene> load_sweep_scene(const std::filesystem::path& path);

}  // namespace gi
