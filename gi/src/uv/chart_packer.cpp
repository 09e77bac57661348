#include "uv/chart_packer.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace gi {

std::optional<ShelfPacking> pack_shelves(std::span<const glm::ivec2> sizes, int width, int height, int padding) {
  std::vector<std::size_t> order(sizes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (sizes[a].y != sizes[b].y) return sizes[a].y > sizes[b].y;
    if (sizes[a].x != sizes[b].x) return sizes[a].x > sizes[b].x;
    return a < b;
  });
  ShelfPacking out;
  out.width = width;
  out.height = height;
  out.origins.assign(sizes.size(), glm::ivec2(0));
  std::int64_t x = padding, y = padding, shelf_height = 0;
  for (std::size_t i : order) {
    const glm::ivec2 s = sizes[i];
    if (x + s.x + padding > width) {  // next shelf
      y += shelf_height + padding;
      x = padding;
      shelf_height = 0;
    }
    if (x + s.x + padding > width || y + s.y + padding > height) return std::nullopt;
    out.origins[i] = glm::ivec2(static_cast<int>(x), static_cast<int>(y));
    x += s.x + padding;
    shelf_height = std::max<std::int64_t>(shelf_height, s.y);
  }
  return out;
}

std::optional<ShelfPacking> pack_growing(std::span<const glm::ivec2> sizes, int padding, int max_size) {
  std::int64_t area = 0;
  for (glm::ivec2 s : sizes) area += std::int64_t{s.x + padding} * (s.y + padding);
  int side = 16;
  while (side < max_size && std::int64_t{side} * side < area) side *= 2;
  int w = std::min(side, max_size), h = w;
  while (true) {
    if (auto p = pack_shelves(sizes, w, h, padding)) return p;
    if (w >= max_size && h >= max_size) return std::nullopt;
    if (w <= h && w < max_size)
      w = std::min(2 * w, max_size);
    else
      h = std::min(2 * h, max_size);
  }
}

}  // namespace gi
