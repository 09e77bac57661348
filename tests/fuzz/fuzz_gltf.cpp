// Fuzz target: the glTF/GLB loader (engine::load_gltf) with KHR_draco_mesh_compression,
// KHR_lights_punctual and the "gi" node extras. An input starting with the GLB magic is
// written as scene.glb, anything else as scene.gltf (its external URIs resolve inside the
// scratch directory, where nothing else lives). Check: a scene that loads is written again
// as a GLB by engine::write_gltf and loads back with the same counts (of meshes with primitives).
#include <engine/gltf.h>

#include <cstring>
#include <string>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::filesystem::path path = gi_fuzz::write_scratch(glb ? "scene.glb" : "scene.gltf", data, size);
  engine::Result<engine::SceneAsset> scene = engine::load_gltf(path);
  if (!scene) {
    gi_fuzz::refused(scene.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  const std::filesystem::path again = gi_fuzz::scratch_dir() / "again.glb";
  if (engine::Status s = engine::write_gltf(*scene, again, {.binary = true}); !s)
    gi_fuzz::fail("write_gltf refused a scene load_gltf accepted: " + s.error().to_string());
  engine::Result<engine::SceneAsset> back = engine::load_gltf(again);
  if (!back) gi_fuzz::fail("the re-written scene does not load: " + back.error().to_string());
  // Meshes without primitives (only points or lines in the file) are not written.
  const auto drawable = [](const engine::SceneAsset& a) {
    std::size_t n = 0;
    for (const engine::Mesh& m : a.meshes) n += m.primitives.empty() ? 0 : 1;
    return n;
  };
  if (drawable(*back) != drawable(*scene) || back->nodes.size() != scene->nodes.size() ||
      back->materials.size() != scene->materials.size() || back->lights.size() != scene->lights.size())
    gi_fuzz::fail("the re-written scene has other counts");
  return 0;
}
