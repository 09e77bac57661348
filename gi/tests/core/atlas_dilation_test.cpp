// Dilation of atlas images, and the seam guarantee: a constant field written into the valid
// texels and dilated reads back constant through GL_LINEAR-style bilinear lookups anywhere on
// triangle edges and vertices (the chart seams) of every scene.
#include "uv/atlas_dilation.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace {

// GL_LINEAR with GL_CLAMP_TO_EDGE on a width x height image: texel centres at (x + 0.5) / w.
template <class Texel>
Texel sample_bilinear(const std::vector<Texel>& img, int w, int h, glm::vec2 uv) {
  const float x = uv.x * float(w) - 0.5f, y = uv.y * float(h) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  auto at = [&](int i, int j) {
    i = std::clamp(i, 0, w - 1);
    j = std::clamp(j, 0, h - 1);
    return img[static_cast<std::size_t>(j * w + i)];
  };
  const int x0 = int(fx), y0 = int(fy);
  return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

}  // namespace

TEST(AtlasDilation, FillsRingByRingFromTheMeanOfValidNeighbours) {
  const int w = 5, h = 5;
  std::vector<float> img(25, 0.0f);
  std::vector<std::uint8_t> valid(25, 0);
  img[12] = 4.0f;  // centre
  valid[12] = 1;
  img[13] = 8.0f;  // right of centre
  valid[13] = 1;
  const auto one = gi::dilate<float>(img, w, h, valid, 1);
  EXPECT_FLOAT_EQ(img[11], 4.0f) << "left of centre sees only the centre";
  EXPECT_FLOAT_EQ(img[14], 8.0f) << "right edge sees only (3, 2)";
  EXPECT_FLOAT_EQ(img[7], 6.0f) << "above the centre sees both";
  EXPECT_FLOAT_EQ(img[0], 0.0f) << "two rings away: untouched after one iteration";
  EXPECT_EQ(one[0], 0);
  EXPECT_EQ(one[6], 1);
  const auto two = gi::dilate<float>(img, w, h, one, 1);
  EXPECT_TRUE(std::all_of(two.begin(), two.end(), [](std::uint8_t v) { return v == 1; }));
  EXPECT_FLOAT_EQ(img[0], 4.0f) << "(0,0) only touches the ring value at (1,1) = 4";
}

TEST(AtlasDilation, EachFilledTexelNamesTheValidTexelItsValueComesFrom) {
  // Two valid texels on a 6 x 3 image: (1, 1) and (4, 1); three rings.
  const int w = 6, h = 3;
  std::vector<std::uint8_t> valid(18, 0);
  valid[7] = 1;
  valid[10] = 1;
  const std::vector<std::int32_t> src = gi::dilation_sources(w, h, valid, 3);
  EXPECT_EQ(src[7], 7);
  EXPECT_EQ(src[10], 10);
  EXPECT_EQ(src[0], 7) << "(0, 0) touches only (1, 1)";
  EXPECT_EQ(src[5], 10) << "(5, 0) touches only (4, 1)";
  EXPECT_EQ(src[8], 7) << "(2, 1) is next to (1, 1) only";
  EXPECT_EQ(src[9], 10) << "(3, 1) is next to (4, 1) only";
  // The same rings as dilate(): a one-hot image of each source dilates into exactly its texels.
  for (std::int32_t s : {7, 10}) {
    std::vector<float> img(18, 0.0f);
    img[static_cast<std::size_t>(s)] = 1.0f;
    gi::dilate<float>(img, w, h, valid, 3);
    for (std::size_t i = 0; i < img.size(); ++i) {
      if (src[i] == s) {
        EXPECT_GT(img[i], 0.0f) << "texel " << i << " named " << s;
      }
    }
  }
  // Not reached within the rings: -1.
  const std::vector<std::int32_t> one = gi::dilation_sources(w, h, std::vector<std::uint8_t>(18, 0), 2);
  EXPECT_TRUE(std::all_of(one.begin(), one.end(), [](std::int32_t v) { return v == -1; }));
  EXPECT_EQ(gi::atlas_gutter_rings(2), 4);
  EXPECT_EQ(gi::atlas_gutter_rings(6), 6);
}

TEST(AtlasDilation, LeavesValidTexelsAndEmptyImagesAlone) {
  std::vector<glm::vec4> img(16, glm::vec4(1.0f, 2.0f, 3.0f, 4.0f));
  std::vector<std::uint8_t> valid(16, 1);
  gi::dilate<glm::vec4>(img, 4, 4, valid, 3);
  for (const glm::vec4& v : img) EXPECT_EQ(v, glm::vec4(1.0f, 2.0f, 3.0f, 4.0f));
  std::vector<glm::vec3> none(16, glm::vec3(0.0f));
  const auto mask = gi::dilate<glm::vec3>(none, 4, 4, std::vector<std::uint8_t>(16, 0), 5);
  EXPECT_TRUE(std::all_of(mask.begin(), mask.end(), [](std::uint8_t v) { return v == 0; }));
}

TEST(AtlasDilation, ConstantIrradianceReadsBackConstantAtChartSeamsOfEveryScene) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(GI_SOURCE_DIR "/assets"))
    if (e.path().extension() == ".gltf") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 6u);
  const glm::vec4 constant(0.25f, 0.5f, 0.75f, 1.0f);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    auto asset = engine::load_gltf(file, {.load_images = false});
    ASSERT_TRUE(asset.ok()) << asset.error().to_string();
    const auto inputs = gi::atlas_inputs_from(gi::bake_input_from(asset.value()));
    auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 8.0f});
    ASSERT_TRUE(layout.ok()) << layout.error().to_string();
    const gi::AtlasTexels texels = gi::rasterize_atlas(layout.value(), inputs);
    const int w = texels.width, h = texels.height;
    std::vector<glm::vec4> img(texels.valid.size(), glm::vec4(0.0f));  // black where empty
    for (std::size_t i = 0; i < img.size(); ++i)
      if (texels.valid[i]) img[i] = constant;
    gi::dilate<glm::vec4>(img, w, h, texels.valid, 1);

    int reads = 0, wrong = 0;
    for (const gi::AtlasMeshUv& m : layout->meshes)
      for (std::size_t t = 0; t < m.indices.size() / 3; ++t) {
        const glm::vec2 a = m.uv1[m.indices[3 * t]], b = m.uv1[m.indices[3 * t + 1]], c = m.uv1[m.indices[3 * t + 2]];
        const glm::vec2 corners[3] = {a, b, c};
        for (int e = 0; e < 3; ++e)
          for (int s = 0; s <= 16; ++s) {  // vertices and points along every edge
            const float f = float(s) / 16.0f;
            const glm::vec2 uv = glm::mix(corners[e], corners[(e + 1) % 3], f);
            const glm::vec4 v = sample_bilinear(img, w, h, uv);
            ++reads;
            if (glm::length(v - constant) > 1e-5f) ++wrong;
          }
      }
    EXPECT_GT(reads, 0);
    EXPECT_EQ(wrong, 0) << "of " << reads << " bilinear reads on chart seams";
  }
}
