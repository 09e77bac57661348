#include "prm/prm_panes.h"

#include <algorithm>
#include <numeric>

namespace gi {

PrmTiles prm_tiles(std::span<const std::uint32_t> texels, int width, int tile_texels) {
  const auto w = static_cast<std::uint32_t>(std::max(width, 1));
  const auto side = static_cast<std::uint32_t>(std::max(tile_texels, 1));
  const std::uint32_t tiles_x = (w + side - 1) / side;
  const auto tile_of = [&](std::uint32_t t) { return (t / w) / side * tiles_x + (t % w) / side; };
  PrmTiles out;
  out.elements.resize(texels.size());
  std::iota(out.elements.begin(), out.elements.end(), 0u);
  // Texels ascend, so a stable sort by tile keeps each tile's elements ascending.
  std::stable_sort(out.elements.begin(), out.elements.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return tile_of(texels[a]) < tile_of(texels[b]); });
  for (std::size_t j = 0; j < out.elements.size(); ++j)
    if (j == 0 || tile_of(texels[out.elements[j]]) != tile_of(texels[out.elements[j - 1]]))
      out.first.push_back(static_cast<std::uint32_t>(j));
  out.first.push_back(static_cast<std::uint32_t>(out.elements.size()));
  return out;
}

void PrmPanes::index_values() {
  block_value.resize(blocks.size());
  std::uint64_t at = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    block_value[b] = at;
    at += blocks[b] < tiles.tiles() ? tiles.size(blocks[b]) : 0;
  }
}

PrmPanes sparse_panes(std::span<const std::uint32_t> texels, int width, int clusters, std::span<const float> dense,
                      const PrmBlockSettings& settings) {
  PrmPanes p;
  p.blocks_settings = settings;
  p.tiles = prm_tiles(texels, width, settings.tile_texels);
  const std::size_t n = texels.size();
  p.cluster_first.push_back(0);
  for (std::size_t c = 0; c < static_cast<std::size_t>(std::max(clusters, 0)); ++c) {
    const std::span<const float> pane = dense.subspan(c * n * 3, n * 3);
    const float peak = pane.empty() ? 0.0f : *std::max_element(pane.begin(), pane.end());
    const float floor = settings.threshold * peak;
    for (std::size_t k = 0; k < p.tiles.tiles(); ++k) {
      float largest = 0.0f;
      for (std::uint32_t j = p.tiles.first[k]; j < p.tiles.first[k + 1]; ++j)
        for (int ch = 0; ch < 3; ++ch) largest = std::max(largest, pane[p.tiles.elements[j] * 3 + ch]);
      if (!(largest > floor) || !(largest > 0.0f)) continue;
      p.blocks.push_back(static_cast<std::uint32_t>(k));
      for (std::uint32_t j = p.tiles.first[k]; j < p.tiles.first[k + 1]; ++j)
        for (int ch = 0; ch < 3; ++ch) p.values.push_back(pane[p.tiles.elements[j] * 3 + ch]);
    }
    p.cluster_first.push_back(static_cast<std::uint32_t>(p.blocks.size()));
  }
  p.index_values();
  return p;
}

std::vector<float> dense_panes(const PrmPanes& panes, std::size_t elements, int clusters) {
  std::vector<float> out(static_cast<std::size_t>(std::max(clusters, 0)) * elements * 3, 0.0f);
  for (std::size_t c = 0; c < panes.cluster_count() && c < static_cast<std::size_t>(std::max(clusters, 0)); ++c)
    for (std::uint32_t b = panes.cluster_first[c]; b < panes.cluster_first[c + 1]; ++b) {
      const std::uint32_t k = panes.blocks[b];
      for (std::uint32_t j = 0; j < panes.tiles.size(k); ++j)
        for (std::size_t ch = 0; ch < 3; ++ch)
          out[(c * elements + panes.tiles.elements[panes.tiles.first[k] + j]) * 3 + ch] =
              panes.values[(panes.block_value[b] + j) * 3 + ch];
    }
  return out;
}

PrmPanes with_values(const PrmPanes& panes, std::size_t elements, std::span<const float> dense) {
  PrmPanes out = panes;
  for (std::size_t c = 0; c < panes.cluster_count(); ++c)
    for (std::uint32_t b = panes.cluster_first[c]; b < panes.cluster_first[c + 1]; ++b) {
      const std::uint32_t k = panes.blocks[b];
      for (std::uint32_t j = 0; j < panes.tiles.size(k); ++j)
        for (std::size_t ch = 0; ch < 3; ++ch)
          out.values[(panes.block_value[b] + j) * 3 + ch] =
              dense[(c * elements + panes.tiles.elements[panes.tiles.first[k] + j]) * 3 + ch];
    }
  return out;
}

}  // namespace gi
