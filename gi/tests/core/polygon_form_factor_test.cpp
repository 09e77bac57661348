// Lambert's point-to-polygon form factor (core/polygon_form_factor.h) against closed forms:
// a disc on the axis, an unbounded plane, a polygon behind the point, and the clipping of a
// polygon that straddles the point's tangent plane.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/polygon_form_factor.h"

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// A regular k-gon of radius r around c in the plane y = c.y.
std::vector<glm::vec3> ring(glm::vec3 c, float r, int k) {
  std::vector<glm::vec3> out;
  for (int i = 0; i < k; ++i) {
    const float a = 2.0f * kPi * static_cast<float>(i) / static_cast<float>(k);
    out.push_back(c + glm::vec3(r * std::cos(a), 0.0f, r * std::sin(a)));
  }
  return out;
}

TEST(PolygonFormFactor, AnOctagonAboveThePointIsTheInscribedDiscsClosedForm) {
  // A disc of radius R at height h on the axis: F = R^2 / (R^2 + h^2). A regular octagon lies
  // between the disc it is inscribed in and the disc inscribed in it.
  const glm::vec3 p(0.0f), n(0.0f, 1.0f, 0.0f);
  const float h = 1.0f, r = 1.0f;
  const std::vector<glm::vec3> oct = ring(glm::vec3(0.0f, h, 0.0f), r, 8);
  const float f = gi::polygon_form_factor(p, n, oct);
  const float inner = r * std::cos(kPi / 8.0f);
  EXPECT_LT(f, r * r / (r * r + h * h));
  EXPECT_GT(f, inner * inner / (inner * inner + h * h));
  // Either winding.
  const std::vector<glm::vec3> back(oct.rbegin(), oct.rend());
  EXPECT_FLOAT_EQ(gi::polygon_form_factor(p, n, back), f);
}

TEST(PolygonFormFactor, ASquareOfSideTwoAtHeightOneIsTheClosedForm) {
  // A square centred over the point, parallel to its plane: four times the textbook corner
  // rectangle's F = (1/2pi)[X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))]
  // with X, Y its sides over the height.
  const float x = 1.0f, y = 1.0f;  // a / h for the quarter
  const float quarter = (x / std::sqrt(1.0f + x * x) * std::atan(y / std::sqrt(1.0f + x * x)) +
                         y / std::sqrt(1.0f + y * y) * std::atan(x / std::sqrt(1.0f + y * y))) /
                        (2.0f * kPi);
  const std::vector<glm::vec3> sq = {
      {-1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {-1.0f, 1.0f, 1.0f}};
  EXPECT_NEAR(gi::polygon_form_factor(glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f), sq), 4.0f * quarter, 1e-5f);
}

TEST(PolygonFormFactor, AHugePlaneIsOneAndAPolygonBehindIsZero) {
  const glm::vec3 p(0.0f), n(0.0f, 1.0f, 0.0f);
  const std::vector<glm::vec3> plane = {
      {-1e4f, 1.0f, -1e4f}, {1e4f, 1.0f, -1e4f}, {1e4f, 1.0f, 1e4f}, {-1e4f, 1.0f, 1e4f}};
  EXPECT_NEAR(gi::polygon_form_factor(p, n, plane), 1.0f, 1e-3f);
  std::vector<glm::vec3> below = plane;
  for (glm::vec3& v : below) v.y = -1.0f;
  EXPECT_EQ(gi::polygon_form_factor(p, n, below), 0.0f);
  EXPECT_EQ(gi::polygon_form_factor(p, n, std::vector<glm::vec3>(plane.begin(), plane.begin() + 2)), 0.0f);
}

TEST(PolygonFormFactor, APolygonAcrossTheTangentPlaneCountsOnlyItsPartInFront) {
  // A wall square x = 1, y in [-1, 1], z in [-1, 1] seen from the origin facing up: only its
  // upper half counts (without the clip, Lambert's sum weighs the lower half negative and the
  // two halves cancel).
  const glm::vec3 p(0.0f), n(0.0f, 1.0f, 0.0f);
  const std::vector<glm::vec3> wall = {
      {1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {1.0f, -1.0f, 1.0f}};
  const std::vector<glm::vec3> upper = {
      {1.0f, 0.0f, -1.0f}, {1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {1.0f, 0.0f, 1.0f}};
  const float f = gi::polygon_form_factor(p, n, wall);
  EXPECT_GT(f, 0.05f);
  EXPECT_NEAR(f, gi::polygon_form_factor(p, n, upper), 1e-6f);
  // A point on the floor at the foot of a vast wall: the wall fills the half of the hemisphere
  // towards +x, whose cosine-weighted share is 1/2.
  const std::vector<glm::vec3> big = {
      {1e-3f, 0.0f, -1e3f}, {1e-3f, 1e3f, -1e3f}, {1e-3f, 1e3f, 1e3f}, {1e-3f, 0.0f, 1e3f}};
  EXPECT_NEAR(gi::polygon_form_factor(p, n, big), 0.5f, 2e-3f);
}

}  // namespace
