// The projection floor of the per-leaf output (antiradiance_texel_blend.h): a field that is
// constant per leaf comes back unchanged, structure inside a leaf does not.
#include <gtest/gtest.h>

#include <vector>

#include "antiradiance/antiradiance_texel_blend.h"

namespace {

// Texel t (of 8) lies on leaf t / 4, blended 3:1 with the other leaf.
std::vector<gi::AntiradianceTexelBlend> two_leaves() {
  std::vector<gi::AntiradianceTexelBlend> blends;
  for (std::uint32_t t = 0; t < 8; ++t) {
    gi::AntiradianceTexelBlend b;
    b.texel = t;
    const int own = static_cast<int>(t / 4);
    b.leaves = glm::ivec4(own, 1 - own, -1, -1);
    b.weights = glm::vec4(0.75f, 0.25f, 0.0f, 0.0f);
    blends.push_back(b);
  }
  return blends;
}

TEST(AntiradianceTexelBlend, ProjectionKeepsWhatIsConstantPerLeafBlended) {
  const auto blends = two_leaves();
  std::vector<glm::vec3> field(8);
  for (std::size_t t = 0; t < 8; ++t) field[t] = glm::vec3(t < 4 ? 1.0f : 3.0f);
  const std::vector<std::uint8_t> use(8, 1);
  const auto out = gi::project_through_leaves(blends, field, use, 2);
  ASSERT_EQ(out.size(), 8u);
  // Leaf means 1 and 3, blended 3:1 with the other leaf.
  EXPECT_FLOAT_EQ(out[0].x, 0.75f * 1.0f + 0.25f * 3.0f);
  EXPECT_FLOAT_EQ(out[7].x, 0.75f * 3.0f + 0.25f * 1.0f);
}

TEST(AntiradianceTexelBlend, ProjectionLosesStructureInsideALeafAndSkipsUnusedTexels) {
  const auto blends = two_leaves();
  // A ramp inside leaf 0, leaf 1 not used at all: leaf 0's mean 1.5 everywhere on it, and
  // leaf 1 (no used texel) drops out of the blend (weights renormalized).
  std::vector<glm::vec3> field(8, glm::vec3(100.0f));
  for (std::size_t t = 0; t < 4; ++t) field[t] = glm::vec3(static_cast<float>(t));
  std::vector<std::uint8_t> use(8, 0);
  for (std::size_t t = 0; t < 4; ++t) use[t] = 1;
  const auto out = gi::project_through_leaves(blends, field, use, 2);
  for (std::size_t t = 0; t < 4; ++t) EXPECT_FLOAT_EQ(out[t].x, 1.5f) << t;
  for (std::size_t t = 4; t < 8; ++t) EXPECT_EQ(out[t].x, 0.0f) << t;
}

}  // namespace
