// The container step of the glTF loader: checks the path, splits a .glb into its chunks
// (glTF 2.0 §4.4), parses and pre-validates the JSON, then lets tinygltf load buffers and
// images. Everything tinygltf would index without a bounds check (buffer views, Draco
// buffer views, GLB chunk lengths) is checked here first.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <system_error>

#include <engine/json_depth.h>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

std::uint32_t read_u32_le(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) | (std::uint32_t{p[3]} << 24);
}

void append_u32_le(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFu));
}

/// Reads a whole regular file, refusing directories, special files and files over the limit.
Result<std::vector<std::uint8_t>> read_regular_file(const Context& ctx, const fs::path& path, const std::string& what) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return ctx.error(what, "file does not exist: " + path.string());
  if (fs::is_directory(status)) return ctx.error(what, "is a directory, not a file: " + path.string());
  if (!fs::is_regular_file(status)) return ctx.error(what, "not a regular file: " + path.string());
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) return ctx.error(what, "cannot read the size of " + path.string() + ": " + ec.message());
  if (size > ctx.options.limits.max_file_bytes) {
    return ctx.error(what, "file of " + std::to_string(size) + " bytes exceeds the limit of " +
                               std::to_string(ctx.options.limits.max_file_bytes) + " bytes");
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (!in) return ctx.error(what, "cannot open " + path.string());
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size))) {
    return ctx.error(what, "cannot read " + path.string());
  }
  return bytes;
}

struct Container {
  std::string json_text;
  std::vector<std::uint8_t> bin;  ///< GLB BIN chunk (empty for .gltf or when absent)
  bool binary = false;
};

/// Splits a GLB (glTF 2.0 §4.4): 12-byte header, a JSON chunk, an optional BIN chunk;
/// unknown chunk types are skipped as the spec requires.
Result<Container> split_glb(const Context& ctx, const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 12) {
    return ctx.error("GLB header",
                     "truncated: the 12-byte header needs 12 bytes, the file has " + std::to_string(bytes.size()));
  }
  const std::uint32_t version = read_u32_le(bytes.data() + 4);
  const std::uint32_t length = read_u32_le(bytes.data() + 8);
  if (version != 2) return ctx.error("GLB header", "unsupported GLB version " + std::to_string(version));
  if (length > bytes.size()) {
    return ctx.error("GLB header", "truncated: header says " + std::to_string(length) + " bytes, the file has " +
                                       std::to_string(bytes.size()));
  }
  // Bytes after `length` are not part of the GLB (the validator warns, it is not an error).
  if (length < 12) return ctx.error("GLB header", "length " + std::to_string(length) + " is shorter than the header");
  Container out;
  out.binary = true;
  bool have_json = false;
  bool have_bin = false;
  std::size_t offset = 12;
  int chunk_index = 0;
  while (offset < length) {
    const std::string where = "GLB chunk " + std::to_string(chunk_index);
    if (length - offset < 8) return ctx.error(where, "truncated chunk header");
    const std::uint32_t chunk_length = read_u32_le(bytes.data() + offset);
    const std::uint32_t chunk_type = read_u32_le(bytes.data() + offset + 4);
    offset += 8;
    if (chunk_length > length - offset) {
      return ctx.error(where, "truncated chunk data: chunk says " + std::to_string(chunk_length) + " bytes, " +
                                  std::to_string(length - offset) + " remain");
    }
    if (chunk_length % 4 != 0) {
      return ctx.error(where, "chunk length " + std::to_string(chunk_length) + " is not a multiple of 4");
    }
    const std::uint8_t* data = bytes.data() + offset;
    if (chunk_index == 0 && chunk_type != kChunkJson) return ctx.error(where, "first chunk is not JSON");
    if (chunk_type == kChunkJson) {
      if (have_json) return ctx.error(where, "second JSON chunk");
      if (chunk_length == 0) return ctx.error(where, "empty JSON chunk");
      out.json_text.assign(reinterpret_cast<const char*>(data), chunk_length);
      have_json = true;
    } else if (chunk_type == kChunkBin) {
      if (have_bin) return ctx.error(where, "second BIN chunk");
      if (chunk_index != 1) return ctx.error(where, "BIN chunk must directly follow the JSON chunk");
      out.bin.assign(data, data + chunk_length);
      have_bin = true;
    }
    offset += chunk_length;
    ++chunk_index;
  }
  if (!have_json) return ctx.error("GLB", "no JSON chunk");
  return out;
}

bool is_integer(const Json& v) { return v.is_number_integer() || v.is_number_unsigned(); }

/// JSON does not distinguish 4 from 4.0 (glTF 2.0 §3.2 allows integers written as floats);
/// tinygltf does, so integral floats are rewritten as integers before it sees them.
void integralize(Json& v) {
  if (v.is_number_float()) {
    const double d = v.get<double>();
    if (std::isfinite(d) && std::floor(d) == d && std::abs(d) < 9.0e15) v = static_cast<std::int64_t>(d);
  } else if (v.is_array() || v.is_object()) {
    for (Json& child : v) integralize(child);
  }
}

/// Integer member; absent -> fallback; not a non-negative integer -> Error.
Result<std::int64_t> index_member(const Context& ctx, const Json& object, const char* key, std::int64_t fallback,
                                  const std::string& location) {
  const Json* v = find_member(object, key);
  if (v == nullptr) return fallback;
  if (!is_integer(*v) || v->get<std::int64_t>() < 0) {
    return ctx.error(location, std::string("'") + key + "' must be a non-negative integer");
  }
  return v->get<std::int64_t>();
}

/// Why tinygltf cannot load buffer `index` (it would reject the whole file), or "".
std::string buffer_problem(const Container& container, const Json& buffer, std::size_t index) {
  const Json* uri = find_member(buffer, "uri");
  if (uri == nullptr) {
    if (container.binary && index == 0) return container.bin.empty() ? "the GLB has no BIN chunk" : "";
    return "it has no 'uri'";
  }
  if (!uri->is_string()) return "'uri' is not a string";
  const std::string u = uri->get<std::string>();
  if (u.rfind("data:", 0) == 0) {
    // The data URIs tinygltf decodes: base64 with these media types.
    for (const char* prefix :
         {"data:application/octet-stream;base64,", "data:application/gltf-buffer;base64,", "data:image/jpeg;base64,",
          "data:image/png;base64,", "data:image/bmp;base64,", "data:image/gif;base64,", "data:text/plain;base64,"}) {
      if (u.rfind(prefix, 0) == 0) return "";
    }
    return "unsupported data URI encoding (base64 octet-stream or gltf-buffer expected)";
  }
  if (u.find("://") != std::string::npos) return "remote URI '" + u + "' is not supported";
  return "";
}

namespace {

// Images a material's texture samples (the slots the loader reads: base colour,
// metallic-roughness, normal, emissive): only these are decoded, so a file's unused
// images cost neither time nor memory.
std::vector<bool> used_images(const Json& doc, std::size_t image_count) {
  std::vector<bool> used(image_count, false);
  const Json* materials = find_member(doc, "materials");
  const Json* textures = find_member(doc, "textures");
  if (materials == nullptr || !materials->is_array() || textures == nullptr || !textures->is_array()) return used;
  const auto mark = [&](const Json* info) {
    if (info == nullptr || !info->is_object()) return;
    const Json* index = find_member(*info, "index");
    if (index == nullptr || !index->is_number_integer()) return;
    const auto t = index->get<std::int64_t>();
    if (t < 0 || static_cast<std::size_t>(t) >= textures->size()) return;
    const Json& texture = (*textures)[static_cast<std::size_t>(t)];
    const Json* source = texture.is_object() ? find_member(texture, "source") : nullptr;
    if (source == nullptr || !source->is_number_integer()) return;
    const auto s = source->get<std::int64_t>();
    if (s >= 0 && static_cast<std::size_t>(s) < image_count) used[static_cast<std::size_t>(s)] = true;
  };
  for (const Json& m : *materials) {
    if (!m.is_object()) continue;
    if (const Json* pbr = find_member(m, "pbrMetallicRoughness"); pbr != nullptr && pbr->is_object()) {
      mark(find_member(*pbr, "baseColorTexture"));
      mark(find_member(*pbr, "metallicRoughnessTexture"));
    }
    mark(find_member(m, "normalTexture"));
    mark(find_member(m, "emissiveTexture"));
  }
  return used;
}

}  // namespace

std::size_t array_size(const Json& doc, const char* key) {
  const Json* a = find_member(doc, key);
  return a != nullptr && a->is_array() ? a->size() : 0;
}

/// asset.version must be a 2.x string.
Status check_asset(const Context& ctx, const Json& doc) {
  const Json* asset = find_member(doc, "asset");
  const Json* version = asset != nullptr ? find_member(*asset, "version") : nullptr;
  if (version == nullptr || !version->is_string()) return ctx.error("asset", "missing asset.version");
  if (version->get<std::string>().rfind("2.", 0) != 0) {
    return ctx.error("asset", "unsupported glTF version '" + version->get<std::string>() + "' (need 2.x)");
  }
  return {};
}

/// The node count against the limit.
Status check_node_count(const Context& ctx, const Json& doc) {
  if (array_size(doc, "nodes") > ctx.options.limits.max_nodes) {
    return ctx.error("nodes", std::to_string(array_size(doc, "nodes")) + " nodes exceed the limit of " +
                                  std::to_string(ctx.options.limits.max_nodes));
  }
  return {};
}

/// The top-level collections, where present, are arrays of objects.
Status check_top_level_arrays(const Context& ctx, const Json& doc) {
  for (const char* key : {"buffers", "bufferViews", "accessors", "meshes", "nodes", "materials", "images", "textures",
                          "cameras", "scenes", "samplers"}) {
    const Json* a = find_member(doc, key);
    if (a != nullptr && !a->is_array()) return ctx.error(key, "must be an array");
    if (a == nullptr) continue;
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (!(*a)[i].is_object()) return ctx.error(std::string(key) + " " + std::to_string(i), "must be an object");
    }
  }
  return {};
}

/// buffers: each byteLength (returned in order); buffers tinygltf cannot load become placeholders
/// with their problem in out.buffer_problems.
Result<std::vector<std::int64_t>> check_buffers(const Context& ctx, const Container& container, ParsedFile& out) {
  Json& doc = out.doc;
  std::vector<std::int64_t> buffer_lengths;
  if (Json* buffers = doc.contains("buffers") ? &doc["buffers"] : nullptr) {
    for (std::size_t i = 0; i < buffers->size(); ++i) {
      const std::string where = "buffer " + std::to_string(i);
      auto len = index_member(ctx, (*buffers)[i], "byteLength", -1, where);
      if (!len) return len.error();
      if (*len < 1) return ctx.error(where, "'byteLength' is required and must be >= 1");
      buffer_lengths.push_back(*len);
      out.buffer_problems.push_back(buffer_problem(container, (*buffers)[i], i));
      if (!out.buffer_problems.back().empty()) {
        (*buffers)[i] = Json{{"byteLength", 3}, {"uri", "data:application/octet-stream;base64,AAAA"}};
      }
    }
  }
  return buffer_lengths;
}

/// The buffer views check_buffer_views() accepted.
struct BufferViews {
  std::size_t count = 0;
  std::vector<std::size_t> buffer;  ///< Per view, its buffer.
};

/// bufferViews: buffer index, byte range inside the buffer (§3.6.1.1), byteStride (§5.11).
Result<BufferViews> check_buffer_views(const Context& ctx, const Json& doc,
                                       const std::vector<std::int64_t>& buffer_lengths) {
  BufferViews out;
  if (const Json* views = find_member(doc, "bufferViews")) {
    out.count = views->size();
    for (std::size_t i = 0; i < views->size(); ++i) {
      const std::string where = "bufferView " + std::to_string(i);
      const Json& view = (*views)[i];
      auto buffer = index_member(ctx, view, "buffer", -1, where);
      if (!buffer) return buffer.error();
      if (*buffer < 0 || static_cast<std::size_t>(*buffer) >= buffer_lengths.size()) {
        return ctx.error(where,
                         "'buffer' missing or out of range (" + std::to_string(buffer_lengths.size()) + " buffers)");
      }
      auto offset = index_member(ctx, view, "byteOffset", 0, where);
      if (!offset) return offset.error();
      auto length = index_member(ctx, view, "byteLength", -1, where);
      if (!length) return length.error();
      if (*length < 1) return ctx.error(where, "'byteLength' is required and must be >= 1");
      out.buffer.push_back(static_cast<std::size_t>(*buffer));
      const std::int64_t buffer_length = buffer_lengths[static_cast<std::size_t>(*buffer)];
      if (*offset > buffer_length || *length > buffer_length - *offset) {
        return ctx.error(where, "byte range [" + std::to_string(*offset) + ", " + std::to_string(*offset + *length) +
                                    ") is out of range of buffer " + std::to_string(*buffer) + " (" +
                                    std::to_string(buffer_length) + " bytes)");
      }
      auto stride = index_member(ctx, view, "byteStride", 0, where);
      if (!stride) return stride.error();
      // §5.11: byteStride is 4..252 and a multiple of 4.
      if (find_member(view, "byteStride") != nullptr && (*stride < 4 || *stride > 252 || *stride % 4 != 0)) {
        return ctx.error(where, "'byteStride' " + std::to_string(*stride) + " must be a multiple of 4 in [4, 252]");
      }
    }
  }
  return out;
}

/// A URI reference's percent-encoded octets decoded (RFC 3986 §2.1), as a file path.
std::string percent_decoded(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    const auto hex = [](char c) {
      return c >= '0' && c <= '9'   ? c - '0'
             : c >= 'a' && c <= 'f' ? c - 'a' + 10
             : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                    : -1;
    };
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out.push_back(static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2])));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

/// Why a relative-file URI would read outside the scene's folder, or empty: an absolute path
/// (a leading '/' or '\\', a drive letter, a file: scheme) or '..' components that climb
/// above the folder (checked lexically, after percent-decoding, with '\\' as a separator).
std::string uri_leaves_folder(const std::string& uri) {
  if (uri.rfind("data:", 0) == 0) return "";
  const std::string path = percent_decoded(uri);
  if (path.rfind("file:", 0) == 0) return "it is a file: URI (absolute)";
  if (!path.empty() && (path[0] == '/' || path[0] == '\\')) return "it is an absolute path";
  if (path.size() >= 2 && path[1] == ':') return "it is an absolute path (drive letter)";
  int depth = 0;
  std::size_t start = 0;
  while (start <= path.size()) {
    std::size_t end = path.find_first_of("/\\", start);
    if (end == std::string::npos) end = path.size();
    const std::string part = path.substr(start, end - start);
    if (part == "..") {
      if (--depth < 0) return "its '..' components climb above the scene's folder";
    } else if (!part.empty() && part != ".") {
      ++depth;
    }
    start = end + 1;
  }
  return "";
}

/// images: the buffer view in range, reading a buffer that has data, and a URI that stays in
/// the scene's folder (GltfLoadOptions::allow_uris_outside_folder).
Status check_images(const Context& ctx, const Json& doc, const BufferViews& views,
                    const std::vector<std::string>& buffer_problems) {
  if (const Json* images = find_member(doc, "images")) {
    for (std::size_t i = 0; i < images->size(); ++i) {
      const std::string where = "image " + std::to_string(i);
      if (const Json* uri = find_member((*images)[i], "uri"); uri != nullptr && uri->is_string()) {
        const std::string why = uri_leaves_folder(uri->get<std::string>());
        if (!why.empty() && !ctx.options.allow_uris_outside_folder) {
          return ctx.error(where + " '" + uri->get<std::string>() + "'",
                           "refused: the URI leaves the scene's folder (" + why +
                               "); set GltfLoadOptions::allow_uris_outside_folder to allow it");
        }
      }
      auto view = index_member(ctx, (*images)[i], "bufferView", -1, where);
      if (!view) return view.error();
      if (*view >= 0 && static_cast<std::size_t>(*view) >= views.count) {
        return ctx.error(where, "'bufferView' " + std::to_string(*view) + " is out of range");
      }
      // tinygltf hands the view's bytes to the decoder without a check: a buffer without
      // data (a placeholder) must not be read here.
      if (*view >= 0) {
        const std::size_t b = views.buffer[static_cast<std::size_t>(*view)];
        if (!buffer_problems[b].empty()) {
          return ctx.error(where, "reads buffer " + std::to_string(b) + ", which has no data: " + buffer_problems[b]);
        }
      }
    }
  }
  return {};
}

/// accessors: the buffer view in range; an unknown type or componentType becomes a harmless
/// placeholder with its problem in out.accessor_problems.
Status check_accessors(const Context& ctx, std::size_t view_count, ParsedFile& out) {
  Json& doc = out.doc;
  if (Json* accessors = doc.contains("accessors") ? &doc["accessors"] : nullptr) {
    static const char* const kTypes[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    for (std::size_t i = 0; i < accessors->size(); ++i) {
      Json& acc = (*accessors)[i];
      const std::string where = "accessor " + std::to_string(i);
      auto view = index_member(ctx, acc, "bufferView", -1, where);
      if (!view) return view.error();
      if (*view >= 0 && static_cast<std::size_t>(*view) >= view_count) {
        return ctx.error(where, "'bufferView' " + std::to_string(*view) + " is out of range (" +
                                    std::to_string(view_count) + " buffer views)");
      }
      std::string problem;
      const Json* type = find_member(acc, "type");
      const Json* component = find_member(acc, "componentType");
      if (type == nullptr || !type->is_string() ||
          std::none_of(std::begin(kTypes), std::end(kTypes),
                       [&](const char* t) { return type->get<std::string>() == t; })) {
        problem = "unknown or missing accessor type";
      }
      if (component == nullptr || !is_integer(*component) ||
          (component->get<std::int64_t>() < 5120 || component->get<std::int64_t>() > 5126 ||
           component->get<std::int64_t>() == 5124)) {
        problem = "unknown or missing componentType";
      }
      if (!problem.empty()) {  // tinygltf would reject the whole file; unused, it is harmless
        acc["type"] = "SCALAR";
        acc["componentType"] = 5126;
      }
      out.accessor_problems.push_back(problem);
    }
  }
  return {};
}

/// textures: source image and sampler in range.
Status check_textures(const Context& ctx, const Json& doc) {
  if (const Json* textures = find_member(doc, "textures")) {
    for (std::size_t i = 0; i < textures->size(); ++i) {
      const std::string where = "texture " + std::to_string(i);
      auto source = index_member(ctx, (*textures)[i], "source", -1, where);
      if (!source) return source.error();
      if (*source >= 0 && static_cast<std::size_t>(*source) >= array_size(doc, "images")) {
        return ctx.error(where, "'source' " + std::to_string(*source) + " refers to a missing image");
      }
      auto sampler = index_member(ctx, (*textures)[i], "sampler", -1, where);
      if (!sampler) return sampler.error();
      if (*sampler >= 0 && static_cast<std::size_t>(*sampler) >= array_size(doc, "samplers")) {
        return ctx.error(where, "'sampler' " + std::to_string(*sampler) + " refers to a missing sampler");
      }
    }
  }
  return {};
}

/// Primitive p of mesh m: material, indices and attribute accessors in range (§3.7.2.1); its
/// indices move from the JSON into out.primitive_indices.
Status check_primitive_references(const Context& ctx, std::size_t m, std::size_t p, Json& prim, ParsedFile& out) {
  const Json& doc = out.doc;
  const std::string pwhere = "mesh " + std::to_string(m) + " primitive " + std::to_string(p);
  auto material = index_member(ctx, prim, "material", -1, pwhere);
  if (!material) return material.error();
  if (*material >= 0 && static_cast<std::size_t>(*material) >= array_size(doc, "materials")) {
    return ctx.error(pwhere, "material " + std::to_string(*material) + " is out of range");
  }
  const std::size_t accessor_count = array_size(doc, "accessors");
  auto indices_ref = index_member(ctx, prim, "indices", -1, pwhere);
  if (!indices_ref) return indices_ref.error();
  if (*indices_ref >= 0 && static_cast<std::size_t>(*indices_ref) >= accessor_count) {
    return ctx.error(pwhere, "indices accessor " + std::to_string(*indices_ref) + " is out of range");
  }
  if (const Json* attrs = find_member(prim, "attributes"); attrs != nullptr && attrs->is_object()) {
    for (const auto& [name, value] : attrs->items()) {
      if (!is_integer(value) || value.get<std::int64_t>() < 0 || value.get<std::uint64_t>() >= accessor_count) {
        return ctx.error(pwhere, "attribute " + name + " refers to a missing accessor");
      }
    }
  }
  if (prim.contains("indices")) {
    auto indices =
        index_member(ctx, prim, "indices", -1, "mesh " + std::to_string(m) + " primitive " + std::to_string(p));
    if (!indices) return indices.error();
    out.primitive_indices[{static_cast<int>(m), static_cast<int>(p)}] = static_cast<int>(*indices);
    prim.erase("indices");
  }
  return {};
}

/// Primitive p of mesh m's KHR_draco_mesh_compression, if any: buffer view in range, attribute
/// ids; moved from the JSON into out.draco.
Status take_draco_extension(const Context& ctx, std::size_t m, std::size_t p, Json& prim, std::size_t view_count,
                            ParsedFile& out) {
  if (!prim.contains("extensions") || !prim["extensions"].is_object()) return {};
  Json& exts = prim["extensions"];
  if (!exts.contains("KHR_draco_mesh_compression")) return {};
  const std::string where =
      "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + " KHR_draco_mesh_compression";
  const Json& ext = exts["KHR_draco_mesh_compression"];
  DracoRef ref;
  auto view = index_member(ctx, ext, "bufferView", -1, where);
  if (!view) return view.error();
  if (*view < 0 || static_cast<std::size_t>(*view) >= view_count) {
    return ctx.error(where, "'bufferView' missing or out of range");
  }
  ref.buffer_view = static_cast<int>(*view);
  const Json* attrs = find_member(ext, "attributes");
  if (attrs == nullptr || !attrs->is_object()) return ctx.error(where, "'attributes' must be an object");
  for (const auto& [name, id] : attrs->items()) {
    if (!is_integer(id) || id.get<std::int64_t>() < 0 || id.get<std::int64_t>() > 1 << 20) {
      return ctx.error(where, "attribute '" + name + "' must be a non-negative integer id");
    }
    ref.attributes[name] = id.get<int>();
  }
  out.draco[{static_cast<int>(m), static_cast<int>(p)}] = std::move(ref);
  exts.erase("KHR_draco_mesh_compression");
  return {};
}

/// meshes: every primitive's references and Draco extension, used or not (§3.7.2.1).
Status check_meshes(const Context& ctx, std::size_t view_count, ParsedFile& out) {
  Json& doc = out.doc;
  if (Json* meshes = doc.contains("meshes") ? &doc["meshes"] : nullptr) {
    for (std::size_t m = 0; m < meshes->size(); ++m) {
      Json* prims = (*meshes)[m].contains("primitives") ? &(*meshes)[m]["primitives"] : nullptr;
      if (prims == nullptr || !prims->is_array()) continue;
      for (std::size_t p = 0; p < prims->size(); ++p) {
        Json& prim = (*prims)[p];
        if (!prim.is_object()) continue;
        // References are checked for every mesh, used or not (§3.7.2.1).
        if (auto ok = check_primitive_references(ctx, m, p, prim, out); !ok) return ok;
        if (auto ok = take_draco_extension(ctx, m, p, prim, view_count, out); !ok) return ok;
      }
    }
  }
  return {};
}

/// Checks the references tinygltf follows while parsing without bounds checks: buffer views
/// against their buffers (§3.6.1.1: byteOffset + byteLength <= buffer.byteLength) and image
/// buffer views. Removes Draco extensions and primitive indices from `doc` into `out`, and
/// turns buffers tinygltf cannot load (no URI, remote, unusual data URIs) into placeholders
/// that are an error only when read. One section after another, each stopping at its first error.
Status prevalidate(const Context& ctx, const Container& container, ParsedFile& out) {
  if (auto ok = check_asset(ctx, out.doc); !ok) return ok;
  if (auto ok = check_node_count(ctx, out.doc); !ok) return ok;
  if (auto ok = check_top_level_arrays(ctx, out.doc); !ok) return ok;
  auto buffer_lengths = check_buffers(ctx, container, out);
  if (!buffer_lengths) return buffer_lengths.error();
  auto views = check_buffer_views(ctx, out.doc, *buffer_lengths);
  if (!views) return views.error();
  if (auto ok = check_images(ctx, out.doc, *views, out.buffer_problems); !ok) return ok;
  if (auto ok = check_accessors(ctx, views->count, out); !ok) return ok;
  if (auto ok = check_textures(ctx, out.doc); !ok) return ok;
  return check_meshes(ctx, views->count, out);
}

// tinygltf file-system callbacks: no shell expansion of URIs, no reads of directories or
// files over the size limit.
std::string expand_path_verbatim(const std::string& path, void*) { return path; }

bool read_external_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto* ctx = static_cast<const Context*>(user);
  auto bytes = read_regular_file(*ctx, fs::path(path), "external file");
  if (!bytes) {
    if (err != nullptr) *err += bytes.error().message + "\n";
    return false;
  }
  *out = std::move(bytes.value());
  return true;
}

/// A clean in-memory GLB (header, padded JSON, padded BIN) for tinygltf, built from the
/// validated chunks, so tinygltf never sees inconsistent lengths.
std::vector<std::uint8_t> rebuild_glb(const std::string& json, const std::vector<std::uint8_t>& bin) {
  std::string padded_json = json;
  while (padded_json.size() % 4 != 0) padded_json.push_back(' ');
  std::vector<std::uint8_t> padded_bin = bin;
  while (padded_bin.size() % 4 != 0) padded_bin.push_back(0);
  std::vector<std::uint8_t> out;
  const std::size_t total = 12 + 8 + padded_json.size() + (padded_bin.empty() ? 0 : 8 + padded_bin.size());
  out.reserve(total);
  append_u32_le(out, kGlbMagic);
  append_u32_le(out, 2);
  append_u32_le(out, static_cast<std::uint32_t>(total));
  append_u32_le(out, static_cast<std::uint32_t>(padded_json.size()));
  append_u32_le(out, kChunkJson);
  out.insert(out.end(), padded_json.begin(), padded_json.end());
  if (!padded_bin.empty()) {
    append_u32_le(out, static_cast<std::uint32_t>(padded_bin.size()));
    append_u32_le(out, kChunkBin);
    out.insert(out.end(), padded_bin.begin(), padded_bin.end());
  }
  return out;
}

std::string first_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

bool declares_extension(const Json& doc, const char* name) {
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    const Json* list = find_member(doc, key);
    if (list == nullptr || !list->is_array()) continue;
    for (const Json& e : *list) {
      if (e.is_string() && e.get<std::string>() == name) return true;
    }
  }
  return false;
}

}  // namespace

const Json* find_member(const Json& object, const char* key) {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

Result<double> number_member(const Context& ctx, const Json& object, const char* key, double fallback,
                             const std::string& location) {
  const Json* v = find_member(object, key);
  if (v == nullptr) return fallback;
  if (!v->is_number()) return ctx.error(location, std::string("'") + key + "' must be a number");
  return v->get<double>();
}

// Long because it is one sequence from bytes to the tinygltf model (container, byte order mark,
// JSON, depth, prevalidation, image limits, file callbacks, parse), each step returning its own error.
Result<ParsedFile> parse_file(const Context& ctx, const fs::path& path) {
  auto bytes = read_regular_file(ctx, path, "");
  if (!bytes) return bytes.error();
  if (bytes->empty()) return ctx.error("", "empty file");

  Container container;
  const bool glb_magic = bytes->size() >= 4 && read_u32_le(bytes->data()) == kGlbMagic;
  if (glb_magic) {
    auto split = split_glb(ctx, *bytes);
    if (!split) return split.error();
    container = std::move(split.value());
  } else {
    container.json_text.assign(reinterpret_cast<const char*>(bytes->data()), bytes->size());
  }
  bytes->clear();

  // glTF 2.0 §3.1 / §4.4.3.1: the JSON is UTF-8 without a byte order mark.
  if (container.json_text.rfind("\xEF\xBB\xBF", 0) == 0) {
    return ctx.error(glb_magic ? "GLB JSON chunk" : "JSON", "bad JSON: starts with a UTF-8 byte order mark");
  }
  ParsedFile out;
  try {
    out.doc = Json::parse(container.json_text);
  } catch (const Json::exception& e) {
    const bool glb_extension = path.extension() == ".glb";
    return ctx.error(
        glb_magic ? "GLB JSON chunk" : "JSON",
        std::string(glb_extension && !glb_magic ? "not a GLB (bad magic) and " : "") + "bad JSON: " + e.what());
  }
  if (!out.doc.is_object()) return ctx.error("JSON", "the root is not a JSON object");
  // Real glTF nests a handful of levels (extras a few more); the walks below recurse.
  constexpr std::size_t kMaxJsonDepth = 256;
  if (engine::json_depth(out.doc, kMaxJsonDepth) > kMaxJsonDepth)
    return ctx.error("JSON", "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  integralize(out.doc);
  if (auto ok = prevalidate(ctx, container, out); !ok) return ok.error();
  out.mesh_quantization = declares_extension(out.doc, "KHR_mesh_quantization");

  // Lights are read from the JSON by the loader (gltf_load_lights.cpp); tinygltf's own
  // parser rejects valid spot lights that rely on the default cone angles.
  Json for_tinygltf = out.doc;
  if (Json* exts = for_tinygltf.contains("extensions") ? &for_tinygltf["extensions"] : nullptr;
      exts != nullptr && exts->is_object()) {
    exts->erase("KHR_lights_punctual");
  }
  const std::string stripped = for_tinygltf.dump();
  ImageDecodeState& images = out.images;
  images.decode = ctx.options.load_images;
  images.max_dimension = ctx.options.limits.max_image_dimension;
  images.max_pixels = ctx.options.limits.max_image_pixels;
  images.max_total_bytes = ctx.options.limits.max_scene_image_bytes;
  const std::size_t image_count = array_size(out.doc, "images");
  images.failures.resize(image_count);
  images.delivered.resize(image_count, false);
  images.used = used_images(out.doc, image_count);

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&decode_image_callback, &images);
  tinygltf::FsCallbacks callbacks{};
  callbacks.FileExists = &tinygltf::FileExists;
  callbacks.ExpandFilePath = &expand_path_verbatim;
  callbacks.ReadWholeFile = &read_external_file;
  callbacks.WriteWholeFile = &tinygltf::WriteWholeFile;
  callbacks.user_data = const_cast<Context*>(&ctx);  // read only by read_external_file
  loader.SetFsCallbacks(callbacks);

  std::string err;
  std::string warn;
  const std::string base_dir = path.parent_path().string();
  bool ok = false;
  try {
    if (container.binary) {
      const std::vector<std::uint8_t> glb = rebuild_glb(stripped, container.bin);
      if (glb.size() > 0xFFFFFFF0u) return ctx.error("GLB", "file too large for GLB (4 GiB)");
      ok = loader.LoadBinaryFromMemory(&out.model, &err, &warn, glb.data(), static_cast<unsigned int>(glb.size()),
                                       base_dir);
    } else {
      ok = loader.LoadASCIIFromString(&out.model, &err, &warn, stripped.data(),
                                      static_cast<unsigned int>(stripped.size()), base_dir);
    }
  } catch (const std::exception& e) {
    return ctx.error("", std::string("glTF parser failed: ") + e.what());
  }
  if (!ok) return ctx.error("", "glTF parser failed: " + first_line(err.empty() ? warn : err));

  return out;
}

}  // namespace engine::gltf_load
