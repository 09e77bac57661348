#pragma once
// Shelf packing of chart footprints (integer texel rectangles) into one atlas, with a gutter
// of `padding` texels between footprints and between footprints and the atlas border.
//   std::optional<gi::ShelfPacking> p = gi::pack_growing(sizes, 2, 4096);
//   glm::ivec2 corner = p->origins[0];  // min texel of footprint 0

#include <optional>
#include <span>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

struct ShelfPacking {
  int width = 0;
  int height = 0;
  std::vector<glm::ivec2> origins;  ///< Min texel of each footprint, in the order given.
};

/// Packs footprints (width, height >= 1) into a width x height atlas. Footprints are placed
/// tallest first (ties: wider first, then lower index) left to right on shelves (the
/// "shelf next fit" of Jylänki 2010, "A Thousand Ways to Pack the Bin"). nullopt if they
/// do not fit.
std::optional<ShelfPacking> pack_shelves(std::span<const glm::ivec2> sizes, int width, int height, int padding);

/// Packs into the smallest power-of-two atlas tried in the order s x s, 2s x s, 2s x 2s, ...
/// (s: the smallest power of two >= 16 whose area holds the padded footprints), up to
/// max_size x max_size. nullopt if they do not fit at max_size.
std::optional<ShelfPacking> pack_growing(std::span<const glm::ivec2> sizes, int padding, int max_size);

}  // namespace gi
