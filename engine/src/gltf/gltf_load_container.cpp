// The container step of the glTF loader: checks the path, splits a .glb into its chunks
// (glTF 2.0 §4.4), parses the JSON and has it pre-validated (gltf_load_prevalidate.h), then
// lets tinygltf load buffers and images through file callbacks that read only regular files
// under the size limit. GLB chunk lengths are checked here; everything else tinygltf would
// index without a bounds check (buffer views, Draco buffer views) by the pre-validation.

#include <cmath>
#include <cstring>
#include <fstream>
#include <system_error>

#include <engine/json_depth.h>

#include "gltf/gltf_load_internal.h"
#include "gltf/gltf_load_prevalidate.h"

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
