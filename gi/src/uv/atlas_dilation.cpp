#include "uv/atlas_dilation.h"

#include <engine/check.h>

namespace gi {

template <class Texel>
std::vector<std::uint8_t> dilate(std::span<Texel> values, int width, int height, std::span<const std::uint8_t> valid,
                                 int iterations) {
  GI_EXPECTS(width >= 0 && height >= 0, "image size is not negative");
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  GI_EXPECTS(values.size() == n && valid.size() == n, "values and mask hold width x height texels");
  GI_EXPECTS(iterations >= 0, "iterations >= 0");
  std::vector<std::uint8_t> mask(valid.begin(), valid.end());
  std::vector<std::size_t> ring;
  std::vector<Texel> ring_values;
  for (int it = 0; it < iterations; ++it) {
    ring.clear();
    ring_values.clear();
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        if (mask[i]) continue;
        Texel sum(0.0f);
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            const std::size_t j =
                static_cast<std::size_t>(ny) * static_cast<std::size_t>(width) + static_cast<std::size_t>(nx);
            if (!mask[j]) continue;
            sum += values[j];
            ++count;
          }
        if (count == 0) continue;
        ring.push_back(i);
        ring_values.push_back(sum / static_cast<float>(count));
      }
    if (ring.empty()) break;
    for (std::size_t k = 0; k < ring.size(); ++k) {
      values[ring[k]] = ring_values[k];
      mask[ring[k]] = 1;
    }
  }
  return mask;
}

template std::vector<std::uint8_t> dilate<float>(std::span<float>, int, int, std::span<const std::uint8_t>, int);
template std::vector<std::uint8_t> dilate<glm::vec3>(std::span<glm::vec3>, int, int, std::span<const std::uint8_t>,
                                                     int);
template std::vector<std::uint8_t> dilate<glm::vec4>(std::span<glm::vec4>, int, int, std::span<const std::uint8_t>,
                                                     int);

}  // namespace gi
