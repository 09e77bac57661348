// gi::reference_first_hits (gi/reference.h): what the path tracer's rays through the pixel
// centres hit first, for a quad in front of a pinhole camera, worked out by hand.
#include <gtest/gtest.h>
#include <gi/bake_input.h>
#include <gi/reference.h>

namespace {

// A 2 m square at z = -5 (x, y in [-1, 1]), its front facing the camera at the origin.
gi::BakeInput quad_at_five_metres() {
  gi::BakeInput in;
  gi::BakePrimitive p;
  p.positions = {{-1, -1, -5}, {1, -1, -5}, {1, 1, -5}, {-1, 1, -5}};
  p.indices = {0, 1, 2, 0, 2, 3};
  in.meshes.push_back({.name = "quad", .primitives = {p}});
  in.instances.push_back({.name = "quad", .mesh = 0});
  return in;
}

}  // namespace

TEST(ReferenceFirstHits, ThePixelCentresOnTheQuadHitItAtItsDistanceTheOthersSeeTheSky) {
  // 90 degrees over 8 pixels: the centre of column x looks along ndc (2 (x + 0.5) / 8 - 1),
  // i.e. at z = -5 it meets x = 5 ndc; only columns (and rows) 3 and 4 (|ndc| = 0.125) fall
  // on the quad.
  const gi::ReferenceCamera camera{.camera_to_world = glm::mat4(1.0f), .yfov_rad = 1.5707964f, .aspect = 0.0f};
  auto hits = gi::reference_first_hits(quad_at_five_metres(), camera, 8, 8, 2);
  ASSERT_TRUE(hits) << hits.error().to_string();
  ASSERT_EQ(hits->hit.size(), 64u);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * 8 + x);
      const bool on_quad = (x == 3 || x == 4) && (y == 3 || y == 4);
      ASSERT_EQ(hits->hit[i] != 0, on_quad) << "pixel " << x << "," << y;
      if (!on_quad) {
        EXPECT_EQ(hits->position_m[i], glm::vec3(0.0f));
        continue;
      }
      const float ndc_x = 2.0f * (static_cast<float>(x) + 0.5f) / 8.0f - 1.0f;
      const float ndc_y = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / 8.0f;  // rows top to bottom
      EXPECT_NEAR(hits->position_m[i].x, 5.0f * ndc_x, 1e-4f);
      EXPECT_NEAR(hits->position_m[i].y, 5.0f * ndc_y, 1e-4f);
      EXPECT_NEAR(hits->position_m[i].z, -5.0f, 1e-4f);
      EXPECT_NEAR(glm::length(hits->normal[i] - glm::vec3(0, 0, 1)), 0.0f, 1e-5f) << "turned to the camera";
    }
}

TEST(ReferenceFirstHits, RefusesABadImageSize) {
  const gi::ReferenceCamera camera{};
  auto hits = gi::reference_first_hits(quad_at_five_metres(), camera, 0, 8);
  ASSERT_FALSE(hits);
  EXPECT_EQ(hits.error().kind, engine::ErrorKind::Invalid);
}
