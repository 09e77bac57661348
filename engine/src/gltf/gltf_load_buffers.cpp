// The container step's checks of where a glTF file's bytes come from (gltf_load_prevalidate.h):
// buffers (URIs tinygltf can load, or a placeholder), buffer views inside their buffers,
// images (URIs that stay in the scene's folder, buffer views that hold data), and which
// images a material samples.

#include <string>
#include <vector>

#include "gltf/gltf_load_prevalidate.h"

namespace engine::gltf_load {
namespace {

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

}  // namespace

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

}  // namespace engine::gltf_load
