// The generated Cornell box against the measured numbers of
// ../shared/external-assets/README.md (millimetres there, metres here).
#include <gtest/gtest.h>

#include <map>
#include <tuple>

#include <glm/gtc/constants.hpp>

#include "scenes.h"
#include "world_triangles.h"

namespace {

constexpr float kTol = 1e-6f;  // metres: the vertices are the measured ones rounded to float

glm::vec3 mm(float x, float y, float z) { return glm::vec3(x, y, z) / 1000.0f; }

bool has_vertex(const std::vector<scenegen_test::WorldTriangle>& tris, const std::string& node, glm::vec3 v) {
  for (const auto& t : tris)
    if (t.node == node)
      for (const glm::vec3& p : {t.a, t.b, t.c})
        if (glm::length(p - v) < kTol) return true;
  return false;
}

TEST(CornellBoxScene, UsesEveryMeasuredVertex) {
  const auto tris = scenegen_test::world_triangles(scenegen::cornell_box());
  for (const glm::vec3& v : {mm(552.8f, 0, 0), mm(0, 0, 0), mm(0, 0, 559.2f), mm(549.6f, 0, 559.2f), mm(556, 548.8f, 0),
                             mm(556, 548.8f, 559.2f), mm(0, 548.8f, 559.2f), mm(0, 548.8f, 0)})
    EXPECT_TRUE(has_vertex(tris, "walls", v)) << v.x << " " << v.y << " " << v.z;
  for (const glm::vec3& v : {mm(130, 165, 65), mm(82, 165, 225), mm(240, 165, 272), mm(290, 165, 114), mm(130, 0, 65)})
    EXPECT_TRUE(has_vertex(tris, "short_block", v)) << v.x << " " << v.y << " " << v.z;
  for (const glm::vec3& v :
       {mm(423, 330, 247), mm(265, 330, 296), mm(314, 330, 456), mm(472, 330, 406), mm(472, 0, 406)})
    EXPECT_TRUE(has_vertex(tris, "tall_block", v)) << v.x << " " << v.y << " " << v.z;
  // Bounds of the box: x 0..556, y 0..548.8, z 0..559.2 mm.
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const auto& t : tris)
    if (t.node == "walls")
      for (const glm::vec3& p : {t.a, t.b, t.c}) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
  EXPECT_NEAR(lo.x, 0.0f, kTol);
  EXPECT_NEAR(hi.x, 0.556f, kTol);
  EXPECT_NEAR(hi.y, 0.5488f, kTol);
  EXPECT_NEAR(hi.z, 0.5592f, kTol);
}

TEST(CornellBoxScene, BlocksAreClosedAndWallsFaceInside) {
  const auto tris = scenegen_test::world_triangles(scenegen::cornell_box());
  for (const std::string block : {"short_block", "tall_block"}) {
    // Closed: every edge is shared by exactly two triangles, once in each direction.
    std::map<std::tuple<float, float, float, float, float, float>, int> edges;
    int count = 0;
    for (const auto& t : tris) {
      if (t.node != block) continue;
      ++count;
      const glm::vec3 v[3] = {t.a, t.b, t.c};
      for (int i = 0; i < 3; ++i) {
        const glm::vec3 a = v[i], b = v[(i + 1) % 3];
        edges[{a.x, a.y, a.z, b.x, b.y, b.z}] += 1;
      }
    }
    EXPECT_EQ(count, 12) << block;
    for (const auto& [e, n] : edges) {
      const auto [ax, ay, az, bx, by, bz] = e;
      EXPECT_EQ(n, 1) << block;
      EXPECT_EQ(edges.count({bx, by, bz, ax, ay, az}), 1u) << block << " has an open edge";
    }
  }
  const glm::vec3 centre = mm(278, 274.4f, 279.6f);
  for (const auto& t : tris) {
    if (t.node == "walls") {
      EXPECT_GT(glm::dot(t.normal, centre - t.a), 0.0f) << "a wall faces outside";
    }
  }
}

TEST(CornellBoxScene, LightAndCameraMatchTheMeasurements) {
  const engine::SceneAsset s = scenegen::cornell_box();
  const int light = scenegen_test::find_node(s, "light");
  ASSERT_GE(light, 0);
  const engine::Node& ln = s.nodes[static_cast<std::size_t>(light)];
  ASSERT_GE(ln.light, 0);
  const engine::Light& l = s.lights[static_cast<std::size_t>(ln.light)].light;
  EXPECT_EQ(l.type, engine::LightType::Area);
  EXPECT_NEAR(l.area_size_m.x, 0.130f, kTol);  // 343 - 213 mm
  EXPECT_NEAR(l.area_size_m.y, 0.105f, kTol);  // 332 - 227 mm
  const glm::vec3 radiance = l.color * l.intensity;
  EXPECT_NEAR(radiance.x, 18.387f, 1e-4f);
  EXPECT_NEAR(radiance.y, 10.987f, 1e-4f);
  EXPECT_NEAR(radiance.z, 2.754f, 1e-4f);
  const glm::mat4 lm = scenegen_test::world_matrix(s, light);
  const glm::vec3 lc(lm[3]);
  EXPECT_NEAR(lc.x, 0.278f, kTol);
  EXPECT_NEAR(lc.y, 0.5488f, kTol);
  EXPECT_NEAR(lc.z, 0.2795f, kTol);
  const glm::vec3 emit = glm::vec3(lm * glm::vec4(0, 0, -1, 0));
  EXPECT_NEAR(emit.y, -1.0f, 1e-6f);
  // The local X x Y rectangle spans 130 mm along x and 105 mm along z.
  EXPECT_NEAR(std::fabs(glm::vec3(lm * glm::vec4(1, 0, 0, 0)).x), 1.0f, 1e-6f);
  EXPECT_NEAR(std::fabs(glm::vec3(lm * glm::vec4(0, 1, 0, 0)).z), 1.0f, 1e-6f);

  // The emissive quad: same rectangle, 0.1 mm under the ceiling, facing down, same radiance.
  const auto tris = scenegen_test::world_triangles(s);
  int quad_tris = 0;
  for (const auto& t : tris) {
    if (t.node != "light_quad") continue;
    ++quad_tris;
    EXPECT_NEAR(t.normal.y, -1.0f, 1e-6f);
    for (const glm::vec3& p : {t.a, t.b, t.c}) {
      EXPECT_NEAR(p.y, 0.5487f, kTol);
      EXPECT_TRUE(std::fabs(p.x - 0.213f) < kTol || std::fabs(p.x - 0.343f) < kTol);
      EXPECT_TRUE(std::fabs(p.z - 0.227f) < kTol || std::fabs(p.z - 0.332f) < kTol);
    }
  }
  EXPECT_EQ(quad_tris, 2);
  const engine::Node& qn = s.nodes[static_cast<std::size_t>(scenegen_test::find_node(s, "light_quad"))];
  const engine::Material& qm =
      s.materials[static_cast<std::size_t>(s.meshes[static_cast<std::size_t>(qn.mesh)].primitives[0].material)];
  EXPECT_NEAR(qm.emissive.x, 18.387f, 1e-4f);

  const int cam = scenegen_test::find_node(s, "camera");
  ASSERT_GE(cam, 0);
  const engine::Node& cn = s.nodes[static_cast<std::size_t>(cam)];
  ASSERT_GE(cn.camera, 0);
  EXPECT_NEAR(s.cameras[static_cast<std::size_t>(cn.camera)].camera.yfov_rad, glm::radians(39.3077f), 1e-6f);
  const glm::mat4 cm = scenegen_test::world_matrix(s, cam);
  EXPECT_NEAR(cm[3].x, 0.278f, kTol);
  EXPECT_NEAR(cm[3].y, 0.273f, kTol);
  EXPECT_NEAR(cm[3].z, -0.8f, kTol);
  const glm::vec3 view = glm::vec3(cm * glm::vec4(0, 0, -1, 0));  // glTF cameras look along -Z
  EXPECT_NEAR(view.z, 1.0f, 1e-6f);
  EXPECT_NEAR(glm::vec3(cm * glm::vec4(0, 1, 0, 0)).y, 1.0f, 1e-6f);
}

}  // namespace
