// engine::load_gltf: reads a .gltf or .glb file into a SceneAsset. The steps live in
// gltf_load_*.cpp (container, accessors, Draco, meshes, materials, lights, nodes); this
// file runs them in order and guarantees that nothing escapes as an exception.

#include <exception>
#include <new>

#include <engine/gltf.h>

#include "gltf/gltf_load_internal.h"

namespace engine {
namespace {

Result<SceneAsset> load_gltf_unchecked(const gltf_load::Context& ctx, const std::filesystem::path& path) {
  auto parsed = gltf_load::parse_file(ctx, path);
  if (!parsed) return parsed.error();
  const gltf_load::ParsedFile& file = parsed.value();

  SceneAsset scene;
  scene.source = ctx.file;
  auto images = gltf_load::convert_images(ctx, file);
  if (!images) return images.error();
  scene.images = std::move(images.value());
  auto materials = gltf_load::convert_materials(ctx, file);
  if (!materials) return materials.error();
  scene.materials = std::move(materials.value());
  auto meshes = gltf_load::convert_meshes(ctx, file);
  if (!meshes) return meshes.error();
  scene.meshes = std::move(meshes.value());
  if (auto ok = gltf_load::check_texcoord_sets(ctx, scene); !ok) return ok.error();
  std::vector<int> camera_map;
  auto cameras = gltf_load::convert_cameras(ctx, file, camera_map);
  if (!cameras) return cameras.error();
  scene.cameras = std::move(cameras.value());
  auto lights = gltf_load::convert_punctual_lights(ctx, file.doc);
  if (!lights) return lights.error();
  scene.lights = std::move(lights.value());
  if (auto ok = gltf_load::convert_nodes(ctx, file, camera_map, scene); !ok) return ok.error();
  return scene;
}

}  // namespace

Result<SceneAsset> load_gltf(const std::filesystem::path& path, const GltfLoadOptions& options) {
  const gltf_load::Context ctx{path.string(), options};
  try {
    return load_gltf_unchecked(ctx, path);
  } catch (const std::bad_alloc&) {
    return ctx.error("", "out of memory while loading (absurd sizes in the file?)");
  } catch (const std::exception& e) {
    return ctx.error("", std::string("unexpected error while loading: ") + e.what());
  }
}

}  // namespace engine
