// engine::generate_tangents: MikkTSpace's convention (tangent along +u, handedness in w).
#include <gtest/gtest.h>

#include <engine/tangents.h>

namespace {

// A unit quad in the xz plane facing +y, its u along `u_axis` and v along `v_axis`.
struct Quad {
  std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  std::vector<glm::vec3> normals{4, glm::vec3(0, 1, 0)};
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices{0, 2, 1, 0, 3, 2};
};

TEST(Tangents, PointAlongIncreasingUWithRightHandedness) {
  Quad q;
  q.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // u along +x, v along +z
  const auto t = engine::generate_tangents(q.positions, q.normals, q.uvs, q.indices);
  ASSERT_EQ(t.size(), 4u);
  for (const glm::vec4& v : t) {
    EXPECT_NEAR(v.x, 1.0f, 1e-6f);
    EXPECT_NEAR(v.y, 0.0f, 1e-6f);
    EXPECT_NEAR(v.z, 0.0f, 1e-6f);
    // cross(n, t) = cross(+y, +x) = -z, the bitangent (+v) is +z: mirrored.
    EXPECT_EQ(v.w, -1.0f);
  }
  q.uvs = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};  // u along +z, v along +x: cross(+y, +z) = +x
  const auto s = engine::generate_tangents(q.positions, q.normals, q.uvs, q.indices);
  for (const glm::vec4& v : s) {
    EXPECT_NEAR(v.z, 1.0f, 1e-6f);
    EXPECT_EQ(v.w, 1.0f);
  }
}

TEST(Tangents, AreOrthogonalToTheNormalAndSurviveDegenerateUvs) {
  Quad q;
  q.normals = std::vector<glm::vec3>(4, glm::normalize(glm::vec3(0.3f, 1.0f, 0.0f)));
  q.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const glm::vec4& v : engine::generate_tangents(q.positions, q.normals, q.uvs, q.indices)) {
    EXPECT_NEAR(glm::dot(glm::vec3(v), q.normals[0]), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(glm::vec3(v)), 1.0f, 1e-6f);
  }
  q.uvs = std::vector<glm::vec2>(4, glm::vec2(0.5f));  // no UV direction at all
  for (const glm::vec4& v : engine::generate_tangents(q.positions, q.normals, q.uvs, q.indices)) {
    EXPECT_NEAR(glm::dot(glm::vec3(v), q.normals[0]), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(glm::vec3(v)), 1.0f, 1e-6f);
    EXPECT_EQ(v.w, 1.0f);
  }
}

}  // namespace
