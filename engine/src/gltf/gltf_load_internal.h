#pragma once
// Private to the glTF loader: the parsed file and the steps that turn it into a SceneAsset.
// Each step checks what it reads and returns an engine::Error naming the file and the
// glTF object ("accessor 3", "node 7") instead of trusting the data.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
// Same configuration as engine/src/gltf/tinygltf_impl.cpp, so the declarations match.
#ifndef TINYGLTF_ENABLE_DRACO
#define TINYGLTF_ENABLE_DRACO
#endif
#ifndef TINYGLTF_NO_INCLUDE_JSON
#define TINYGLTF_NO_INCLUDE_JSON
#endif
#ifndef TINYGLTF_USE_CPP14
#define TINYGLTF_USE_CPP14
#endif
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wnull-dereference"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wcast-align"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include <engine/gltf.h>
#include <engine/result.h>
#include <engine/scene_asset.h>

namespace engine::gltf_load {

using Json = nlohmann::json;

/// What every step needs: the file name for messages and the caller's options.
struct Context {
  std::string file;
  GltfLoadOptions options;
  /// Accessor elements read so far for the whole file (GltfLoadLimits::max_scene_elements),
  /// and of those, elements without a bufferView (zero-filled, max_unbacked_elements).
  mutable std::size_t elements_read = 0;
  mutable std::size_t unbacked_elements_read = 0;

  Error error(std::string location, std::string message) const {
    return Error{file, std::move(location), std::move(message)};
  }
};

/// A primitive's KHR_draco_mesh_compression object. The loader decodes Draco itself (with
/// bounds checks) instead of letting tinygltf do it, so it is removed from the JSON that
/// tinygltf sees.
struct DracoRef {
  int buffer_view = -1;
  std::map<std::string, int> attributes;  ///< glTF semantic -> Draco attribute unique id
};

/// The file after the container step: the JSON as written, and tinygltf's model of it
/// (buffers loaded, images decoded or skipped, Draco primitives left compressed).
/// Image decoding hook given to tinygltf (decodes to RGBA8 or only records the bytes).
struct ImageDecodeState {
  bool decode = true;
  int max_dimension = 16384;
  std::size_t max_pixels = std::size_t{1} << 26;       ///< GltfLoadLimits::max_image_pixels
  std::size_t max_total_bytes = std::size_t{2} << 30;  ///< GltfLoadLimits::max_scene_image_bytes
  std::size_t decoded_bytes = 0;                       ///< decoded so far (RGBA8)
  std::vector<std::string> failures;                   ///< per image index: empty, or why it failed
  std::vector<bool> delivered;                         ///< per image index: bytes were found
  std::vector<bool> used;  ///< per image index: a material's texture samples it (decoded only then)
};

struct ParsedFile {
  Json doc;
  tinygltf::Model model;
  std::map<std::pair<int, int>, DracoRef> draco;  ///< (mesh, primitive) -> Draco data
  /// (mesh, primitive) -> indices accessor. Removed from what tinygltf sees, because it
  /// rejects valid index accessors without a buffer view (Draco, all-zero indices).
  std::map<std::pair<int, int>, int> primitive_indices;
  /// Per buffer: why it holds no data (no URI, remote URI, unsupported data URI), or empty.
  /// Such buffers are an error only when something reads them.
  std::vector<std::string> buffer_problems;
  /// Per accessor: why it cannot be read (unknown type...), or empty. An error only when used.
  std::vector<std::string> accessor_problems;
  ImageDecodeState images;
  bool mesh_quantization = false;  ///< KHR_mesh_quantization is used
};

// gltf_load_container.cpp: file checks, GLB chunks, JSON pre-validation (gltf_load_prevalidate.cpp,
// gltf_load_buffers.cpp), tinygltf, images.
Result<ParsedFile> parse_file(const Context& ctx, const std::filesystem::path& path);

// gltf_load_accessors.cpp
/// Reads accessor `index` as doubles, `count * components` of them, normalized integers
/// converted as glTF 2.0 §3.11 says, sparse substitution applied (§3.6.2.3).
/// `max_count` bounds the element count.
Result<std::vector<double>> read_accessor(const Context& ctx, const ParsedFile& file, int index, std::size_t max_count);
/// Number of components of an accessor type (SCALAR 1 ... MAT4 16), 0 if unknown.
int component_count(int type);

// gltf_load_draco.cpp
struct DracoPrimitive {
  std::map<std::string, std::vector<float>> attributes;  ///< semantic -> values
  std::map<std::string, int> components;                 ///< semantic -> components
  std::vector<std::uint32_t> indices;
  std::size_t vertex_count = 0;
};
Result<DracoPrimitive> decode_draco(const Context& ctx, const ParsedFile& file, const DracoRef& ref,
                                    const std::string& location);

// gltf_load_meshes.cpp
Result<std::vector<Mesh>> convert_meshes(const Context& ctx, const ParsedFile& file);
/// Area-weighted smooth normals over shared indices (exposed for tests through the loader).
std::vector<glm::vec3> compute_smooth_normals(const std::vector<glm::vec3>& positions,
                                              const std::vector<std::uint32_t>& indices);

// gltf_load_materials.cpp
Result<std::vector<Image>> convert_images(const Context& ctx, const ParsedFile& file);
Result<std::vector<Material>> convert_materials(const Context& ctx, const ParsedFile& file);
/// Every primitive has the TEXCOORD set each texture of its material reads (TextureRef::texcoord).
Status check_texcoord_sets(const Context& ctx, const SceneAsset& scene);
bool decode_image_callback(tinygltf::Image* image, int image_idx, std::string* err, std::string* warn, int req_width,
                           int req_height, const unsigned char* bytes, int size, void* user_data);

// gltf_load_lights.cpp
/// The file's KHR_lights_punctual lights, converted to engine units.
Result<std::vector<NamedLight>> convert_punctual_lights(const Context& ctx, const Json& doc);
/// Perspective cameras; orthographic ones are skipped with a warning (index_map[i] = -1).
Result<std::vector<NamedCamera>> convert_cameras(const Context& ctx, const ParsedFile& file,
                                                 std::vector<int>& index_map);

/// The "gi" object of a node's extras (docs/scene-format.md).
struct GiExtras {
  Mobility mobility = Mobility::Unspecified;
  GiRegion region = GiRegion::None;
  std::optional<bool> light_moves;
  std::optional<NamedLight> area_light;
};
Result<GiExtras> parse_gi_extras(const Context& ctx, const Json& node, const std::string& location);
/// The "gi" object of the chosen scene's extras: the sky into scene.environment, the sun
/// as a directional light on a new root node appended to scene.nodes.
Status parse_scene_environment(const Context& ctx, const Json& scene_json, const std::string& location,
                               SceneAsset& scene);

// gltf_load_nodes.cpp
/// Fills scene.nodes (parents first) and appends area lights to scene.lights.
/// `camera_map` maps file camera indices to scene.cameras (-1: skipped).
Status convert_nodes(const Context& ctx, const ParsedFile& file, const std::vector<int>& camera_map, SceneAsset& scene);

// JSON helpers (gltf_load_json.cpp).
/// The member `key` of `object` if `object` is an object holding it, else nullptr.
const Json* find_member(const Json& object, const char* key);
/// Reads a number member; absent -> `fallback`; present but not a number -> Error.
Result<double> number_member(const Context& ctx, const Json& object, const char* key, double fallback,
                             const std::string& location);
/// A JSON integer, signed or unsigned (not 4.0: integralize those first).
bool is_integer(const Json& v);
/// Integer member; absent -> `fallback`; present but not a non-negative integer -> Error.
Result<std::int64_t> index_member(const Context& ctx, const Json& object, const char* key, std::int64_t fallback,
                                  const std::string& location);
/// The size of the top-level array `key` of `doc`; 0 when absent or not an array.
std::size_t array_size(const Json& doc, const char* key);

}  // namespace engine::gltf_load
