#pragma once
// glTF 2.0 reading and writing (.gltf and .glb), with KHR_lights_punctual,
// KHR_draco_mesh_compression, KHR_materials_emissive_strength and the "gi" node extras.
//   auto scene = engine::load_gltf("assets/cornell_box.gltf");
//   if (!scene) { std::cerr << scene.error().to_string(); return 1; }
//   engine::write_gltf(*scene, "out.glb", {.binary = true, .draco = true});

#include <filesystem>

#include <engine/result.h>
#include <engine/scene_asset.h>

namespace engine {

/// Limits that protect the loader from absurd inputs; exceeding one is a data error.
struct GltfLoadLimits {
  std::size_t max_file_bytes = std::size_t{2} << 30;  ///< 2 GiB
  std::size_t max_vertices_per_primitive = 1u << 26;  ///< 67 M
  std::size_t max_indices_per_primitive = 3u << 26;
  std::size_t max_nodes = 1u << 20;
  int max_image_dimension = 16384;
  /// Pixels of one decoded image: 2^26 (64 M, 256 MiB as RGBA8). Checked from the image's
  /// header before it is decoded; the error names the image and the file.
  std::size_t max_image_pixels = std::size_t{1} << 26;
  /// Bytes of all decoded images of the file together (RGBA8, 4 per pixel): 2 GiB. Checked
  /// before each image is decoded.
  std::size_t max_scene_image_bytes = std::size_t{2} << 30;
  /// Accessor elements (vertex attributes, indices) read in the whole file: 2^28 (268 M).
  /// With the per-primitive limits it bounds the loader's time and memory for any file.
  std::size_t max_scene_elements = std::size_t{1} << 28;
  /// Of those, elements of accessors without a bufferView (zeros, glTF §3.6.2.3) in the whole
  /// file: 2^22 (4 M). They cost memory that no byte of the file pays for.
  std::size_t max_unbacked_elements = std::size_t{1} << 22;
};

struct GltfLoadOptions {
  bool load_images = true;  ///< Decode textures (off: materials keep indices, images are empty).
  /// Image URIs that leave the scene file's folder (an absolute path, or '..' components
  /// that climb above it) are refused unless this is set: a downloaded scene must not read
  /// arbitrary files of the machine. Symbolic links inside the folder are not followed up.
  bool allow_uris_outside_folder = false;
  GltfLoadLimits limits{};
};

/// Loads a .gltf or .glb file. Every malformed input yields an Error naming the file and
/// the problem (bad JSON, missing buffers, out-of-range accessors, truncated data, NaN
/// transforms, absurd counts); nothing throws and nothing crashes.
Result<SceneAsset> load_gltf(const std::filesystem::path& path, const GltfLoadOptions& options = {});

struct GltfWriteOptions {
  bool binary = false;  ///< .glb (one file) instead of .gltf + .bin.
  bool draco = false;   ///< Compress meshes with KHR_draco_mesh_compression.
  int draco_position_bits = 14;
  int draco_normal_bits = 10;
  int draco_texcoord_bits = 12;
};

/// Writes `scene` deterministically (same input, same bytes). Writes to a temporary file
/// and renames, so a failed write leaves nothing behind.
Status write_gltf(const SceneAsset& scene, const std::filesystem::path& path, const GltfWriteOptions& options = {});

}  // namespace engine
