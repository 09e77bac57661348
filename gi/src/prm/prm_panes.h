#pragma once
// Sparse PRM panes (issue 38): a cluster's pane stored only on the atlas tiles (blocks of
// tile x tile texels) its light reaches. A pane's memory then follows what its cluster
// lights, not the whole atlas, and a light change touches only the blocks of the clusters
// it weights. A block of cluster c is kept when its largest channel exceeds
// threshold x the largest channel of pane c (threshold 0: every block holding a non-zero
// value, the dense panes exactly); dropped blocks read 0.
//   gi::PrmPanes p = gi::sparse_panes(texels, width, clusters, dense, {.tile_texels = 8, .threshold = 1e-3f});
//   std::vector<float> back = gi::dense_panes(p, texels.size(), clusters);  // 0 where dropped

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace gi {

/// How panes are cut into blocks and which are kept.
struct PrmBlockSettings {
  int tile_texels = 8;     ///< Block side in atlas texels (1..256).
  float threshold = 0.0f;  ///< Kept: the block's largest channel > threshold x the pane's largest (0..1).
  bool operator==(const PrmBlockSettings&) const = default;
};

/// The pane elements (indices into Prm::texels) grouped by atlas tile.
struct PrmTiles {
  /// tiles()+1 entries: tile k's elements are elements[first[k] .. first[k+1]).
  std::vector<std::uint32_t> first;
  /// Element indices grouped by tile (tiles in row-major order of the tile grid), ascending
  /// within a tile. Only tiles holding an element are listed.
  std::vector<std::uint32_t> elements;
  std::size_t tiles() const { return first.empty() ? 0 : first.size() - 1; }
  std::size_t size(std::size_t k) const { return first[k + 1] - first[k]; }
  bool operator==(const PrmTiles&) const = default;
};

/// The tiles of `texels` (atlas texel indices y x width + x) at `tile_texels` per side.
PrmTiles prm_tiles(std::span<const std::uint32_t> texels, int width, int tile_texels);

/// Every cluster's pane over its kept blocks.
struct PrmPanes {
  PrmBlockSettings blocks_settings;
  PrmTiles tiles;  ///< Derived from Prm::texels and the atlas width (not stored in files).
  /// cluster_count+1 entries: cluster c's blocks are blocks[cluster_first[c] .. cluster_first[c+1]).
  std::vector<std::uint32_t> cluster_first;
  std::vector<std::uint32_t> blocks;  ///< Tile index of each stored block, ascending per cluster.
  /// First element of each stored block in `values` (3 floats per element); derived.
  std::vector<std::uint64_t> block_value;
  /// Block b's element j (tiles.elements[tiles.first[blocks[b]] + j]), channel ch at
  /// values[(block_value[b] + j) * 3 + ch]: irradiance (W/m^2) per unit entry irradiance.
  std::vector<float> values;

  std::size_t cluster_count() const { return cluster_first.empty() ? 0 : cluster_first.size() - 1; }
  /// Elements stored over all clusters (what memory is proportional to).
  std::size_t stored_elements() const { return values.size() / 3; }
  /// Recomputes block_value from tiles and blocks.
  void index_values();
  bool operator==(const PrmPanes&) const = default;
};

/// Sparse panes of the dense `dense` (pane c, element i, channel ch at
/// dense[(c x texels.size() + i) x 3 + ch]).
PrmPanes sparse_panes(std::span<const std::uint32_t> texels, int width, int clusters, std::span<const float> dense,
                      const PrmBlockSettings& settings);

/// The dense panes back (0 in dropped blocks), in `sparse_panes`' `dense` order.
std::vector<float> dense_panes(const PrmPanes& panes, std::size_t elements, int clusters);

/// The same blocks with other values (`dense` in sparse_panes' order): e.g. the panes as the
/// GPU decodes them.
PrmPanes with_values(const PrmPanes& panes, std::size_t elements, std::span<const float> dense);

}  // namespace gi
