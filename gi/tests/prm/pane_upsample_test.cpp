// PRM panes at a coarser density than the atlas, read per chart at the atlas's texels
// (pane_upsample.h): smooth fields carry over, and no light crosses from one chart to the
// next.
#include "prm/pane_upsample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "uv/atlas_dilation.h"

namespace {

// An L: a 2 x 2 m floor (y = 0) and a 2 x 2 m wall (x = 0) meeting along the z axis; two
// meshes, so two charts whichever way the charting groups them.
std::vector<gi::AtlasInputMesh> floor_and_wall() {
  gi::AtlasInputMesh floor{.positions = {{0, 0, 0}, {2, 0, 0}, {2, 0, 2}, {0, 0, 2}},
                           .normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}},
                           .indices = {0, 2, 1, 0, 3, 2},
                           .id = 0};
  gi::AtlasInputMesh wall{.positions = {{0, 0, 0}, {0, 0, 2}, {0, 2, 2}, {0, 2, 0}},
                          .normals = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}},
                          .indices = {0, 2, 1, 0, 3, 2},
                          .id = 1};
  return {floor, wall};
}

struct Layouts {
  gi::AtlasLayout coarse, fine;
  gi::AtlasTexels coarse_texels, fine_texels;
  std::vector<std::uint32_t> coarse_filled;  // covered coarse texels and their dilation rings, as a PRM's panes
};

// A coarse image with values on the covered texels, dilated as bake_prm dilates its panes
// (4 rings): the gutter between charts then holds values of whichever chart is nearer.
std::vector<glm::vec3> dilated(const Layouts& l, std::vector<glm::vec3> image) {
  gi::dilate<glm::vec3>(image, l.coarse.width, l.coarse.height, l.coarse_texels.valid, 4);
  return image;
}

Layouts layouts(float coarse_density, float fine_density) {
  const auto inputs = floor_and_wall();
  Layouts l;
  l.coarse = gi::build_atlas_layout(inputs, {.texels_per_metre = coarse_density}).value();
  l.fine = gi::build_atlas_layout(inputs, {.texels_per_metre = fine_density}).value();
  l.coarse_texels = gi::rasterize_atlas(l.coarse, inputs);
  l.fine_texels = gi::rasterize_atlas(l.fine, inputs);
  std::vector<glm::vec3> ones(l.coarse_texels.valid.size(), glm::vec3(0.0f));
  const std::vector<std::uint8_t> filled =
      gi::dilate<glm::vec3>(ones, l.coarse.width, l.coarse.height, l.coarse_texels.valid, 4);
  for (std::size_t t = 0; t < filled.size(); ++t)
    if (filled[t]) l.coarse_filled.push_back(static_cast<std::uint32_t>(t));
  return l;
}

// A field that jumps by 100x across the corner (a lit floor, a dark wall): every fine texel
// of each surface reads exactly its own surface's value. Plain bilinear reads of the coarse
// image (or reads across the gutter) mix the two along the corner.
TEST(PaneUpsample, NoLightCrossesFromOneChartToTheNext) {
  const Layouts l = layouts(2.0f, 16.0f);
  std::vector<glm::vec3> coarse(l.coarse_texels.valid.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t < coarse.size(); ++t)
    if (l.coarse_texels.valid[t]) coarse[t] = l.coarse_texels.mesh[t] == 0 ? glm::vec3(1.0f) : glm::vec3(100.0f);
  coarse = dilated(l, coarse);
  auto up = gi::PaneUpsampler::build(l.coarse, l.coarse_filled, l.fine, l.fine_texels);
  ASSERT_TRUE(up) << up.error().to_string();
  EXPECT_EQ(up->orphans(), 0u);
  const std::vector<glm::vec3> fine = up->apply(coarse);
  ASSERT_EQ(fine.size(), l.fine_texels.valid.size());
  std::size_t floor = 0, wall = 0;
  for (std::size_t i = 0; i < fine.size(); ++i) {
    if (!l.fine_texels.valid[i]) continue;
    const float expected = l.fine_texels.mesh[i] == 0 ? 1.0f : 100.0f;
    ASSERT_NEAR(fine[i].x, expected, 1e-4f * expected) << "fine texel " << i << " of mesh " << l.fine_texels.mesh[i];
    ++(l.fine_texels.mesh[i] == 0 ? floor : wall);
  }
  EXPECT_GT(floor, 900u);  // 32 x 32 texels each, give or take the conservative borders
  EXPECT_GT(wall, 900u);
}

// A field linear in world space on the floor (a gradient of indirect light) is read back at
// the fine texels within 1% of its range wherever the fine texel lies among coarse texels
// (bilinear is exact on linear data); the fine texels within a coarse texel of the chart's
// edge read the edge's value (no extrapolation), within a coarse texel's step.
TEST(PaneUpsample, ASmoothFieldIsReadBackAtTheFineTexels) {
  const Layouts l = layouts(4.0f, 16.0f);
  const auto field = [](const glm::vec3& p) { return 10.0f + 3.0f * p.x + 1.5f * p.z; };  // 10..19 on the floor
  std::vector<glm::vec3> coarse(l.coarse_texels.valid.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t < coarse.size(); ++t)
    if (l.coarse_texels.valid[t] && l.coarse_texels.mesh[t] == 0)
      coarse[t] = glm::vec3(field(l.coarse_texels.position[t]));
  coarse = dilated(l, coarse);
  auto up = gi::PaneUpsampler::build(l.coarse, l.coarse_filled, l.fine, l.fine_texels);
  ASSERT_TRUE(up) << up.error().to_string();
  const std::vector<glm::vec3> fine = up->apply(coarse);
  const float step = 0.25f * 4.5f;  // one coarse texel (0.25 m) of the steepest slope
  std::size_t interior = 0;
  for (std::size_t i = 0; i < fine.size(); ++i) {
    if (!l.fine_texels.valid[i] || l.fine_texels.mesh[i] != 0) continue;
    const glm::vec3 p = l.fine_texels.position[i];
    const float truth = field(p);
    const bool inner = p.x > 0.25f && p.x < 1.75f && p.z > 0.25f && p.z < 1.75f;
    if (inner) {
      ASSERT_NEAR(fine[i].x, truth, 0.09f) << "fine texel " << i << " at " << p.x << ", " << p.z;
      ++interior;
    } else {
      ASSERT_NEAR(fine[i].x, truth, step) << "fine texel " << i << " at " << p.x << ", " << p.z;
    }
  }
  EXPECT_GT(interior, 500u);
}

TEST(PaneUpsample, LayoutsOfOtherChartsAreRefusedByName) {
  const Layouts l = layouts(2.0f, 8.0f);
  auto one = floor_and_wall();
  one.pop_back();
  const gi::AtlasLayout other = gi::build_atlas_layout(one, {.texels_per_metre = 2.0f}).value();
  auto up = gi::PaneUpsampler::build(other, l.coarse_filled, l.fine, l.fine_texels);
  ASSERT_FALSE(up);
  EXPECT_NE(up.error().to_string().find("different charts"), std::string::npos) << up.error().to_string();
  auto wrong = gi::PaneUpsampler::build(l.coarse, l.coarse_filled, l.fine, l.coarse_texels);
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().to_string().find("not of the atlas layout"), std::string::npos);
  auto good = gi::PaneUpsampler::build(l.coarse, l.coarse_filled, l.fine, l.fine_texels);
  ASSERT_TRUE(good);
  EXPECT_TRUE(good->apply(std::vector<glm::vec3>(3)).empty()) << "a coarse image of the wrong size";
}

}  // namespace

namespace {

// The coarse texels inside the charts' footprints: what a coarse PRM's panes keep (prm.cpp).
std::vector<std::uint32_t> in_footprints(const Layouts& l) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t t : l.coarse_filled) {
    const int x = static_cast<int>(t % static_cast<std::uint32_t>(l.coarse.width));
    const int y = static_cast<int>(t / static_cast<std::uint32_t>(l.coarse.width));
    for (const gi::AtlasChart& c : l.coarse.charts)
      if (x >= c.origin.x && y >= c.origin.y && x < c.origin.x + c.size.x && y < c.origin.y + c.size.y) {
        out.push_back(t);
        break;
      }
  }
  return out;
}

}  // namespace

// Issue 38: the panes' gutter rings outside the footprints are read by no fine texel, so
// coarse panes drop them; the reads and rings built from the footprint texels alone are the
// same records and give the same atlas. The records are the compact GPU form: four 16-bit
// weights on a 2 x 2 block summing to 1, and ring texels the mean of their filled neighbours.
TEST(PaneUpsample, PanesReadOnlyInsideTheFootprintsAndAsFourWeightsAndRingMeans) {
  const Layouts l = layouts(2.0f, 16.0f);
  const std::vector<std::uint32_t> kept = in_footprints(l);
  ASSERT_LT(kept.size(), l.coarse_filled.size()) << "the dilation rings reach past the footprints";
  auto all = gi::PaneUpsampler::build(l.coarse, l.coarse_filled, l.fine, l.fine_texels, 4);
  auto trimmed = gi::PaneUpsampler::build(l.coarse, kept, l.fine, l.fine_texels, 4);
  ASSERT_TRUE(all && trimmed);
  EXPECT_TRUE(*all == *trimmed);
  std::vector<glm::vec3> coarse(l.coarse_texels.valid.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t < coarse.size(); ++t)
    if (l.coarse_texels.valid[t]) coarse[t] = glm::vec3(1.0f + 0.25f * static_cast<float>(t % 7), 2.0f, 0.5f);
  coarse = dilated(l, coarse);
  const std::vector<glm::vec3> fine = trimmed->apply(coarse);
  for (const gi::PaneUpsampler::Read& r : trimmed->reads()) {
    float sum = 0.0f;
    for (float w : r.weight) {
      EXPECT_EQ(w * gi::PaneUpsampler::kWeightSteps, std::round(w * gi::PaneUpsampler::kWeightSteps));
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0f, 4.0f / gi::PaneUpsampler::kWeightSteps);
  }
  ASSERT_EQ(trimmed->ring_first().size(), 5u);
  ASSERT_GT(trimmed->ring_texels().size(), 0u);
  const auto w = static_cast<std::size_t>(l.fine.width);
  for (const gi::PaneUpsampler::RingTexel& r : trimmed->ring_texels()) {
    glm::vec3 mean(0.0f);
    int n = 0;
    for (std::size_t k = 0; k < 8; ++k)
      if (r.neighbours & (1u << k)) {
        const auto d = gi::PaneUpsampler::kNeighbour[k];
        mean += fine[(r.fine / w + static_cast<std::size_t>(d.y)) * w + r.fine % w + static_cast<std::size_t>(d.x)];
        ++n;
      }
    ASSERT_GT(n, 0);
    EXPECT_NEAR(fine[r.fine].x, mean.x / static_cast<float>(n), 1e-5f * mean.x) << r.fine;
  }
}
