// Distributed antiradiance bakes (docs/distributed-bake.md): link_elements_shard computes the
// links to the receivers of a shard's blocks of 64 elements, merge_link_shards puts every
// receiver's run in place: the merged mesh equals link_elements bit for bit for any shard
// count, and a part that is not its shard's is refused.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "antiradiance/antiradiance_region.h"
#include "antiradiance/link_mesh.h"
#include "antiradiance_scenes.h"

namespace {

bool same_links(const gi::LinkMesh& a, const gi::LinkMesh& b) {
  if (a.links.size() != b.links.size() || a.offsets != b.offsets) return false;
  for (std::size_t k = 0; k < a.links.size(); ++k) {
    const gi::Link &x = a.links[k], &y = b.links[k];
    if (x.receiver != y.receiver || x.sender != y.sender || x.bin != y.bin ||
        std::memcmp(&x.form_factor, &y.form_factor, sizeof(float)) != 0)
      return false;
  }
  return a.relinked_elements == b.relinked_elements && a.links_made == b.links_made;
}

class AntiradianceShard : public ::testing::Test {
 protected:
  void SetUp() override {
    settings_.patch_size_m = 1.2f;  // coarse: a few thousand elements
    input_ = artest::corridor(50.0f);
    auto h = gi::build_element_hierarchy(input_, settings_);
    ASSERT_TRUE(h.ok()) << h.error().to_string();
    h_ = std::move(h).value();
  }
  gi::AntiradianceSettings settings_;
  gi::BakeInput input_;
  gi::ElementHierarchy h_;
};

TEST_F(AntiradianceShard, MergedShardsAreTheWholeLinkMeshForOneThreeAndSevenShards) {
  const gi::DirectionalBins bins(settings_.bins_per_side);
  const gi::LinkMesh whole = gi::link_elements(h_, bins, settings_);
  ASSERT_GT(h_.nodes.size(), 7u * 64u) << "every shard should own elements";
  ASSERT_GT(whole.links.size(), 1000u);
  for (std::uint32_t n : {1u, 3u, 7u}) {
    SCOPED_TRACE("N = " + std::to_string(n));
    std::vector<std::vector<gi::Link>> parts;
    std::size_t total = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const gi::WorkShard shard{.index = i, .count = n};
      gi::LinkMesh part = gi::link_elements_shard(h_, bins, settings_, shard);
      for (const gi::Link& l : part.links) {
        ASSERT_TRUE(shard.owns(static_cast<std::size_t>(l.receiver)));
      }
      if (n > 1) {
        EXPECT_LT(part.links.size(), whole.links.size());
      }
      total += part.links.size();
      parts.push_back(std::move(part.links));
    }
    EXPECT_EQ(total, whole.links.size());
    auto merged = gi::merge_link_shards(h_, parts);
    ASSERT_TRUE(merged.ok()) << merged.error().to_string();
    EXPECT_TRUE(same_links(*merged, whole));
  }
}

TEST_F(AntiradianceShard, BakeFromLinkShardsIsTheWholeBake) {
  auto whole = gi::bake_antiradiance(input_, settings_);
  ASSERT_TRUE(whole.ok()) << whole.error().to_string();
  std::vector<std::vector<gi::Link>> parts;
  for (std::uint32_t i = 0; i < 2; ++i) {
    auto part = gi::bake_antiradiance_links_shard(input_, settings_, {.index = i, .count = 2});
    ASSERT_TRUE(part.ok()) << part.error().to_string();
    parts.push_back(std::move(part->links));
  }
  auto merged = gi::bake_antiradiance_from_link_shards(input_, settings_, parts);
  ASSERT_TRUE(merged.ok()) << merged.error().to_string();
  EXPECT_TRUE(same_links(merged->static_links, whole->static_links));
  ASSERT_EQ(merged->baseline.size(), whole->baseline.size());
  EXPECT_EQ(std::memcmp(merged->baseline.data(), whole->baseline.data(), whole->baseline.size() * sizeof(glm::vec3)),
            0);
}

TEST_F(AntiradianceShard, MergeRefusesPartsThatAreNotTheirShards) {
  const gi::DirectionalBins bins(settings_.bins_per_side);
  std::vector<std::vector<gi::Link>> parts;
  for (std::uint32_t i = 0; i < 2; ++i)
    parts.push_back(gi::link_elements_shard(h_, bins, settings_, {.index = i, .count = 2}).links);
  // The parts swapped: every receiver is the other shard's.
  auto swapped = gi::merge_link_shards(h_, {parts[1], parts[0]});
  ASSERT_FALSE(swapped.ok());
  EXPECT_NE(swapped.error().to_string().find("antiradiance shard 0 of 2"), std::string::npos)
      << swapped.error().to_string();
  // Out of order.
  std::vector<std::vector<gi::Link>> unsorted = parts;
  ASSERT_GT(unsorted[1].size(), 2u);
  std::swap(unsorted[1][0], unsorted[1][1]);
  auto bad = gi::merge_link_shards(h_, unsorted);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().to_string().find("not sorted"), std::string::npos) << bad.error().to_string();
  // A sender out of range.
  std::vector<std::vector<gi::Link>> range = parts;
  range[0].back().sender = static_cast<std::int32_t>(h_.nodes.size());
  EXPECT_FALSE(gi::merge_link_shards(h_, range).ok());
}

}  // namespace
