// Bad input to the light-atlas builder gives an engine::Error naming the problem, never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace {

gi::AtlasInputMesh triangle() {
  gi::AtlasInputMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {0, 1, 2};
  m.id = 7;
  return m;
}

std::string error_of(const std::vector<gi::AtlasInputMesh>& inputs, const gi::AtlasSettings& settings = {}) {
  auto r = gi::build_atlas_layout(inputs, settings);
  return r.ok() ? std::string("<no error>") : r.error().to_string();
}

}  // namespace

TEST(AtlasBadInput, NanPositionIsAnError) {
  auto m = triangle();
  m.positions[1].y = std::numeric_limits<float>::quiet_NaN();
  const std::string e = error_of({m});
  EXPECT_NE(e.find("input 0 (id 7)"), std::string::npos) << e;
  EXPECT_NE(e.find("position 1 is not finite"), std::string::npos) << e;
}

TEST(AtlasBadInput, AbsurdlyFarPositionIsAnError) {
  auto m = triangle();
  m.positions[2].z = 1e30f;
  const std::string e = error_of({m});
  EXPECT_NE(e.find("position 2 is farther than"), std::string::npos) << e;
}

TEST(AtlasBadInput, InfiniteNormalIsAnError) {
  auto m = triangle();
  m.normals = {{0, 0, 1}, {0, 0, INFINITY}, {0, 0, 1}};
  EXPECT_NE(error_of({m}).find("normal 1 is not finite"), std::string::npos) << error_of({m});
}

TEST(AtlasBadInput, IndexOutOfRangeIsAnError) {
  auto m = triangle();
  m.indices[2] = 3;
  const std::string e = error_of({m});
  EXPECT_NE(e.find("index 2 is 3, out of range (vertex count 3)"), std::string::npos) << e;
}

TEST(AtlasBadInput, IndexCountNotAMultipleOfThreeIsAnError) {
  auto m = triangle();
  m.indices.push_back(0);
  EXPECT_NE(error_of({m}).find("index count 4 is not a multiple of 3"), std::string::npos) << error_of({m});
}

TEST(AtlasBadInput, NormalCountMismatchIsAnError) {
  auto m = triangle();
  m.normals = {{0, 0, 1}};
  EXPECT_NE(error_of({m}).find("has 1 normals for 3 positions"), std::string::npos) << error_of({m});
}

TEST(AtlasBadInput, AbsurdOrNonPositiveDensityIsAnError) {
  for (float d : {1e9f, 0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(), INFINITY}) {
    const std::string e = error_of({triangle()}, {.texels_per_metre = d});
    EXPECT_NE(e.find("texels_per_metre"), std::string::npos) << d << ": " << e;
  }
  EXPECT_NE(error_of({triangle()}, {.texels_per_metre = 1e9f}).find("is absurd"), std::string::npos);
  EXPECT_NE(error_of({triangle()}, {.texels_per_metre = 0.0f}).find("finite positive"), std::string::npos);
}

TEST(AtlasBadInput, OutOfRangeSettingsAreErrors) {
  EXPECT_NE(error_of({triangle()}, {.padding_texels = -1}).find("padding_texels must be in 0..64"), std::string::npos);
  EXPECT_NE(error_of({triangle()}, {.max_atlas_size = 100000}).find("max_atlas_size must be in 16..16384"),
            std::string::npos);
  EXPECT_NE(error_of({triangle()}, {.chart_max_angle_degrees = 90.0f}).find("chart_max_angle_degrees"),
            std::string::npos);
}

TEST(AtlasBadInput, EmptySceneIsAnError) {
  const std::string expected = "no static triangles to parameterize (empty scene)";
  EXPECT_NE(error_of({}).find(expected), std::string::npos) << error_of({});
  gi::AtlasInputMesh empty;
  EXPECT_NE(error_of({empty}).find(expected), std::string::npos);
  EXPECT_TRUE(gi::atlas_inputs_from(gi::bake_input_from(engine::SceneAsset{})).empty());
}

TEST(AtlasBadInput, TooManyChartsForTheMaxSizeIsAnError) {
  // 2000 separate triangles facing alternating directions need 2000 footprints of at least
  // 1 + 2 padding texels: more than a 16 x 16 atlas holds at any density.
  gi::AtlasInputMesh m;
  for (std::uint32_t i = 0; i < 2000; ++i) {
    const glm::vec3 o(float(i) * 3.0f, 0.0f, 0.0f);
    m.positions.insert(m.positions.end(), {o, o + glm::vec3(1, 0, 0), o + glm::vec3(0, 1, 0)});
    m.indices.insert(m.indices.end(), {3 * i, 3 * i + 1, 3 * i + 2});
  }
  const std::string e = error_of({m}, {.max_atlas_size = 16});
  EXPECT_NE(e.find("2000 charts do not fit a 16 x 16 atlas"), std::string::npos) << e;
}
