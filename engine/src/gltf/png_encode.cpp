// PNG encoding through stb_image_write's in-memory callback.
#include "gltf/png_encode.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#include <stb_image_write.h>
#pragma GCC diagnostic pop

namespace engine::gltf {

std::vector<std::uint8_t> encode_png_rgba8(int width, int height, const std::vector<std::uint8_t>& rgba8) {
  std::vector<std::uint8_t> out;
  auto append = [](void* context, void* data, int size) {
    auto* bytes = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* p = static_cast<const std::uint8_t*>(data);
    bytes->insert(bytes->end(), p, p + size);
  };
  if (stbi_write_png_to_func(append, &out, width, height, 4, rgba8.data(), width * 4) == 0) return {};
  return out;
}

}  // namespace engine::gltf
