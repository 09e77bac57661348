// Fuzz target: the EXR reader (engine::load_exr) the light atlas's light_atlas.exr goes
// through (the loader then checks its size against the layout and its values). Check: an
// image that loads has width x height x 4 pixels and a positive size.
#include <engine/image.h>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_scratch("light_atlas.exr", data, size);
  engine::Result<engine::ImageRgbaF> image = engine::load_exr(path);
  if (!image) {
    gi_fuzz::refused(image.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  if (image->width <= 0 || image->height <= 0 ||
      image->pixels.size() != static_cast<std::size_t>(image->width) * static_cast<std::size_t>(image->height) * 4)
    gi_fuzz::fail("load_exr returned an image whose size does not match its pixels");
  return 0;
}
