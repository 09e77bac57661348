#pragma once
// PNG encoding of 8-bit RGBA pixels for embedding images in glTF files (stb_image_write,
// compiled in tinygltf_impl.cpp). Deterministic: same pixels, same bytes.
//   std::vector<std::uint8_t> png = engine::gltf::encode_png_rgba8(w, h, img.rgba8);

#include <cstdint>
#include <vector>

namespace engine::gltf {

/// Encodes `rgba8` (width x height x 4 bytes, rows top to bottom). Empty on failure.
std::vector<std::uint8_t> encode_png_rgba8(int width, int height, const std::vector<std::uint8_t>& rgba8);

}  // namespace engine::gltf
