#include "uv/atlas_dilation.h"

#include <array>
#include <utility>

#include <engine/check.h>

namespace gi {

namespace {

std::size_t index_of(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
}

// The rings both dilations grow: per iteration, every texel outside `mask` with a neighbour in
// it (8 neighbours, row by row) gets `fill(texel, neighbours)`'s value, stored by `store` after
// the whole ring is computed (a ring never reads its own values), then joins the mask.
template <class Value, class Fill, class Store>
void grow_rings(int width, int height, std::vector<std::uint8_t>& mask, int iterations, Fill&& fill, Store&& store) {
  std::vector<std::pair<std::size_t, Value>> ring;
  std::array<std::size_t, 8> neighbours{};
  for (int it = 0; it < iterations; ++it) {
    ring.clear();
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i = index_of(x, y, width);
        if (mask[i]) continue;
        std::size_t count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            const std::size_t j = index_of(nx, ny, width);
            if (mask[j]) neighbours[count++] = j;
          }
        if (count > 0) ring.emplace_back(i, fill(i, std::span<const std::size_t>(neighbours.data(), count)));
      }
    if (ring.empty()) break;
    for (const auto& [i, value] : ring) {
      store(i, value);
      mask[i] = 1;
    }
  }
}

std::size_t checked_size(int width, int height, std::size_t valid_size, int iterations) {
  GI_EXPECTS(width >= 0 && height >= 0, "image size is not negative");
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  GI_EXPECTS(valid_size == n, "the mask holds width x height texels");
  GI_EXPECTS(iterations >= 0, "iterations >= 0");
  return n;
}

}  // namespace

template <class Texel>
std::vector<std::uint8_t> dilate(std::span<Texel> values, int width, int height, std::span<const std::uint8_t> valid,
                                 int iterations) {
  const std::size_t n = checked_size(width, height, valid.size(), iterations);
  GI_EXPECTS(values.size() == n, "values hold width x height texels");
  std::vector<std::uint8_t> mask(valid.begin(), valid.end());
  grow_rings<Texel>(
      width, height, mask, iterations,
      [&](std::size_t, std::span<const std::size_t> from) {
        Texel sum(0.0f);
        for (std::size_t j : from) sum += values[j];
        return sum / static_cast<float>(from.size());
      },
      [&](std::size_t i, const Texel& v) { values[i] = v; });
  return mask;
}

std::vector<std::int32_t> dilation_sources(int width, int height, std::span<const std::uint8_t> valid, int iterations) {
  const std::size_t n = checked_size(width, height, valid.size(), iterations);
  std::vector<std::int32_t> source(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (valid[i]) source[i] = static_cast<std::int32_t>(i);
  std::vector<std::uint8_t> mask(valid.begin(), valid.end());
  grow_rings<std::int32_t>(
      width, height, mask, iterations, [&](std::size_t, std::span<const std::size_t> from) { return source[from[0]]; },
      [&](std::size_t i, std::int32_t s) { source[i] = s; });
  return source;
}

template std::vector<std::uint8_t> dilate<float>(std::span<float>, int, int, std::span<const std::uint8_t>, int);
template std::vector<std::uint8_t> dilate<glm::vec3>(std::span<glm::vec3>, int, int, std::span<const std::uint8_t>,
                                                     int);
template std::vector<std::uint8_t> dilate<glm::vec4>(std::span<glm::vec4>, int, int, std::span<const std::uint8_t>,
                                                     int);

}  // namespace gi
