#pragma once
// World-space neighbourhoods of atlas texels, for the gather's filter (texel_filter.h) and
// point lookups (irradiance_at_points).
//   const gi::TexelCells cells(texels, valid, radius_m);
//   cells.for_around(cells.cell_of(p), [&](std::uint32_t j) { ... });

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "transport/static_scene.h"

namespace gi {

// Texels bucketed by their sample position into cubic cells (exact integer cells, sorted,
// texels ascending within a cell): the world-space neighbourhoods of the filter and of point
// lookups, visited in a fixed order (bit-identical for any thread count).
class TexelCells {
 public:
  TexelCells(const AtlasTexels& tx, std::span<const std::uint32_t> texels, float cell_m) : cell_(cell_m) {
    for (std::uint32_t i : texels) entries_.push_back({cell_of(tx.position[i]), i});
    std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
      return before(a.cell, b.cell) || (a.cell == b.cell && a.texel < b.texel);
    });
    for (std::size_t k = 0; k < entries_.size(); ++k)
      if (k == 0 || entries_[k].cell != entries_[k - 1].cell) cells_.push_back(entries_[k].cell), first_.push_back(k);
    first_.push_back(entries_.size());
  }
  std::size_t cell_count() const { return cells_.size(); }
  /// Calls fn(texel) for every texel of cell k.
  template <class Fn>
  void for_cell(std::size_t k, Fn&& fn) const {
    for (std::size_t m = first_[k]; m < first_[k + 1]; ++m) fn(entries_[m].texel);
  }
  /// Calls fn(texel) for every texel in the 27 cells around cell c (dz, dy, dx order).
  template <class Fn>
  void for_around(const glm::ivec3& c, Fn&& fn) const {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const glm::ivec3 cc = c + glm::ivec3(dx, dy, dz);
          const auto it = std::lower_bound(cells_.begin(), cells_.end(), cc, before);
          if (it != cells_.end() && *it == cc) for_cell(static_cast<std::size_t>(it - cells_.begin()), fn);
        }
  }
  const glm::ivec3& cell(std::size_t k) const { return cells_[k]; }
  glm::ivec3 cell_of(const glm::vec3& p) const { return glm::ivec3(glm::floor(p / cell_)); }

 private:
  struct Entry {
    glm::ivec3 cell;
    std::uint32_t texel;
  };
  static bool before(const glm::ivec3& a, const glm::ivec3& b) {
    return a.z != b.z ? a.z < b.z : a.y != b.y ? a.y < b.y : a.x < b.x;
  }
  float cell_;
  std::vector<Entry> entries_;
  std::vector<glm::ivec3> cells_;
  std::vector<std::size_t> first_;  // cell k holds entries_[first_[k], first_[k + 1])
};

}  // namespace gi
