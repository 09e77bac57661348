#pragma once
// Private to the glTF loader's container step (gltf_load_container.cpp): what tinygltf would
// index without a bounds check is checked before it parses. gltf_load_prevalidate.cpp walks
// the JSON section by section; gltf_load_buffers.cpp holds the sections about where bytes
// come from (buffers, buffer views, images and their URIs).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {

/// The file split into its JSON and, for a GLB, its BIN chunk (glTF 2.0 §4.4).
struct Container {
  std::string json_text;
  std::vector<std::uint8_t> bin;  ///< GLB BIN chunk (empty for .gltf or when absent)
  bool binary = false;
};

/// Checks the references tinygltf follows while parsing without bounds checks: buffer views
/// against their buffers (§3.6.1.1: byteOffset + byteLength <= buffer.byteLength) and image
/// buffer views. Removes Draco extensions and primitive indices from `doc` into `out`, and
/// turns buffers tinygltf cannot load (no URI, remote, unusual data URIs) into placeholders
/// that are an error only when read. One section after another, each stopping at its first error.
Status prevalidate(const Context& ctx, const Container& container, ParsedFile& out);

// gltf_load_buffers.cpp
/// buffers: each byteLength (returned in order); buffers tinygltf cannot load become placeholders
/// with their problem in out.buffer_problems.
Result<std::vector<std::int64_t>> check_buffers(const Context& ctx, const Container& container, ParsedFile& out);

/// The buffer views check_buffer_views() accepted.
struct BufferViews {
  std::size_t count = 0;
  std::vector<std::size_t> buffer;  ///< Per view, its buffer.
};

/// bufferViews: buffer index, byte range inside the buffer (§3.6.1.1), byteStride (§5.11).
Result<BufferViews> check_buffer_views(const Context& ctx, const Json& doc,
                                       const std::vector<std::int64_t>& buffer_lengths);

/// images: the buffer view in range, reading a buffer that has data, and a URI that stays in
/// the scene's folder (GltfLoadOptions::allow_uris_outside_folder).
Status check_images(const Context& ctx, const Json& doc, const BufferViews& views,
                    const std::vector<std::string>& buffer_problems);

/// Per image: a material's texture samples it (the slots the loader reads: base colour,
/// metallic-roughness, normal, emissive). Only these are decoded, so a file's unused images
/// cost neither time nor memory.
std::vector<bool> used_images(const Json& doc, std::size_t image_count);

}  // namespace engine::gltf_load
