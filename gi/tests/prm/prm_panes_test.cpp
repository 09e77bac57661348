// Sparse PRM panes (issue 38): blocks kept per cluster above a threshold of its peak, the
// dense panes exactly at threshold 0, and the runtime sum over the kept blocks only.
#include "prm/prm_panes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/random.h"
#include "prm/prm.h"
#include "prm/prm_runtime.h"

namespace {

// A 40 x 24 atlas, three texels of four; cluster c's light a bump centred at (8 + 12c, 12)
// of radius ~4 texels over a floor `floor` (0: exact zeros far from the bump).
gi::Prm bump_prm(int clusters, float floor, const gi::PrmBlockSettings& blocks) {
  gi::Prm prm;
  prm.width = 40;
  prm.height = 24;
  prm.cluster_count = clusters;
  prm.cluster_size.assign(static_cast<std::size_t>(clusters), 1);
  prm.settings.pane_tile_texels = blocks.tile_texels;
  prm.settings.pane_threshold = blocks.threshold;
  for (std::uint32_t t = 0; t < 40u * 24u; ++t)
    if (t % 4 != 3) prm.texels.push_back(t);
  const std::size_t n = prm.texels.size();
  std::vector<float> dense(static_cast<std::size_t>(clusters) * n * 3);
  for (std::size_t c = 0; c < static_cast<std::size_t>(clusters); ++c)
    for (std::size_t i = 0; i < n; ++i) {
      const float dx = static_cast<float>(prm.texels[i] % 40) - (8.0f + 12.0f * static_cast<float>(c));
      const float dy = static_cast<float>(prm.texels[i] / 40) - 12.0f;
      const float r2 = dx * dx + dy * dy;
      const float v = r2 < 100.0f ? 100.0f / (1.0f + r2) : floor;
      for (std::size_t ch = 0; ch < 3; ++ch) dense[(c * n + i) * 3 + ch] = v * (1.0f + 0.1f * static_cast<float>(ch));
    }
  gi::set_dense_panes(prm, dense);
  return prm;
}

std::vector<gi::ClusterWeight> all_clusters(int clusters) {
  std::vector<gi::ClusterWeight> w;
  for (int c = 0; c < clusters; ++c)
    w.push_back({static_cast<std::uint32_t>(c), glm::vec3(0.5f + 0.25f * static_cast<float>(c), 1.0f, 0.75f)});
  return w;
}

TEST(PrmPanes, TilesGroupEveryElementOnceAscendingWithinATile) {
  const gi::Prm prm = bump_prm(1, 0.0f, {.tile_texels = 8});
  const gi::PrmTiles& tiles = prm.panes.tiles;
  EXPECT_EQ(tiles.tiles(), 5u * 3u);  // 40 x 24 in 8 x 8 tiles, every tile holds texels
  std::vector<int> seen(prm.texels.size(), 0);
  for (std::size_t k = 0; k < tiles.tiles(); ++k)
    for (std::uint32_t j = tiles.first[k]; j < tiles.first[k + 1]; ++j) {
      const std::uint32_t e = tiles.elements[j];
      ++seen[e];
      const std::uint32_t t = prm.texels[e];
      EXPECT_EQ((t / 40) / 8 * 5 + (t % 40) / 8, k) << "element " << e;
      if (j > tiles.first[k]) {
        EXPECT_LT(prm.texels[tiles.elements[j - 1]], t);
      }
    }
  for (int s : seen) ASSERT_EQ(s, 1);
}

TEST(PrmPanes, ThresholdZeroKeepsTheDensePanesExactly) {
  // Bumps over exact zeros: only the tiles holding light are stored, and nothing is lost.
  const gi::Prm prm = bump_prm(3, 0.0f, {.tile_texels = 8, .threshold = 0.0f});
  const gi::Prm full = bump_prm(3, 0.0f, {.tile_texels = 8, .threshold = 0.0f});
  EXPECT_EQ(gi::dense_panes(prm), gi::dense_panes(full));
  EXPECT_LT(prm.panes.blocks.size(), 3u * 15u) << "all-zero tiles are not stored";
  EXPECT_GT(prm.panes.blocks.size(), 3u * 2u);
  // The sum over the stored blocks equals the dense sum bit for bit (same order per texel).
  const auto w = all_clusters(3);
  const std::vector<float> d = gi::dense_panes(prm);
  std::vector<glm::vec3> expected(40 * 24, glm::vec3(0.0f));
  const std::size_t n = prm.texels.size();
  for (const gi::ClusterWeight& cw : w)
    for (std::size_t i = 0; i < n; ++i)
      expected[prm.texels[i]] += cw.weight * glm::vec3(d[(cw.cluster * n + i) * 3], d[(cw.cluster * n + i) * 3 + 1],
                                                       d[(cw.cluster * n + i) * 3 + 2]);
  EXPECT_EQ(gi::sum_panes(prm, w), expected);
}

TEST(PrmPanes, ABlockIsKeptExactlyWhenItsLightExceedsTheThreshold) {
  // A floor of 0.5 everywhere (0.4% of the 120 peak): threshold 1e-3 keeps it, 1e-2 drops
  // the tiles holding only the floor, and the error is at most the floor at every texel.
  for (const float threshold : {1e-3f, 1e-2f, 0.3f}) {
    const gi::Prm prm = bump_prm(2, 0.5f, {.tile_texels = 8, .threshold = threshold});
    const gi::Prm dense = bump_prm(2, 0.5f, {.tile_texels = 8, .threshold = 0.0f});
    const std::vector<float> kept = gi::dense_panes(prm), all = gi::dense_panes(dense);
    const gi::PrmTiles& tiles = prm.panes.tiles;
    const std::size_t n = prm.texels.size();
    std::size_t stored = 0;
    for (std::size_t c = 0; c < 2; ++c) {
      const float peak = *std::max_element(all.begin() + static_cast<std::ptrdiff_t>(c * n * 3),
                                           all.begin() + static_cast<std::ptrdiff_t>((c + 1) * n * 3));
      for (std::size_t k = 0; k < tiles.tiles(); ++k) {
        float largest = 0.0f;
        bool zero = true;
        for (std::uint32_t j = tiles.first[k]; j < tiles.first[k + 1]; ++j)
          for (std::size_t ch = 0; ch < 3; ++ch) {
            largest = std::max(largest, all[(c * n + tiles.elements[j]) * 3 + ch]);
            zero &= kept[(c * n + tiles.elements[j]) * 3 + ch] == 0.0f;
          }
        const bool expect_kept = largest > threshold * peak;
        EXPECT_EQ(!zero, expect_kept) << "cluster " << c << " tile " << k << " threshold " << threshold;
        stored += expect_kept;
      }
    }
    EXPECT_EQ(prm.panes.blocks.size(), stored);
    EXPECT_EQ(prm.panes.stored_elements() * 3, prm.panes.values.size());
    for (std::size_t j = 0; j < all.size(); ++j)
      ASSERT_LE(all[j] - kept[j], threshold * 120.0f + 1e-6f) << "a dropped value is below threshold x peak";
  }
  EXPECT_EQ(bump_prm(2, 0.5f, {.tile_texels = 8, .threshold = 1e-3f}).panes.blocks.size(), 2u * 15u);
  EXPECT_LT(bump_prm(2, 0.5f, {.tile_texels = 8, .threshold = 1e-2f}).panes.blocks.size(), 2u * 15u);
}

TEST(PrmPanes, WithValuesKeepsTheBlocks) {
  const gi::Prm prm = bump_prm(2, 0.0f, {.tile_texels = 16});
  std::vector<float> doubled = gi::dense_panes(prm);
  for (float& v : doubled) v *= 2.0f;
  const gi::PrmPanes twice = gi::with_values(prm.panes, prm.texels.size(), doubled);
  EXPECT_EQ(twice.blocks, prm.panes.blocks);
  for (std::size_t j = 0; j < twice.values.size(); ++j) ASSERT_EQ(twice.values[j], 2.0f * prm.panes.values[j]);
}

}  // namespace
