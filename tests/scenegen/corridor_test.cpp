// The corridor scene's claim, checked by brute force: no corridor floor point sees the
// alcove lamp, and none sees any surface point that itself sees the lamp, so light reaches
// the corridor floor only after at least two reflections (and leaves it after three).
#include <gtest/gtest.h>

#include <algorithm>

#include "scenes.h"
#include "world_triangles.h"

namespace {

using scenegen_test::WorldTriangle;

struct SurfacePoint {
  glm::vec3 p, n;
  std::string node;
};

bool visible(const SurfacePoint& x, const SurfacePoint& y, const std::vector<WorldTriangle>& occluders) {
  if (glm::dot(x.n, y.p - x.p) <= 0.0f || glm::dot(y.n, x.p - y.p) <= 0.0f) return false;
  return std::none_of(occluders.begin(), occluders.end(),
                      [&](const WorldTriangle& t) { return scenegen_test::segment_hits(x.p, y.p, t); });
}

std::vector<SurfacePoint> samples(const std::vector<WorldTriangle>& tris, float spacing,
                                  bool (*keep)(const std::string&)) {
  std::vector<SurfacePoint> out;
  for (const WorldTriangle& t : tris) {
    if (!keep(t.node)) continue;
    for (const glm::vec3& p : scenegen_test::sample_triangle(t, spacing)) out.push_back({p, t.normal, t.node});
  }
  return out;
}

TEST(CorridorScene, CorridorFloorSeesNeitherTheLampNorAnythingTheLampLights) {
  const engine::SceneAsset scene = scenegen::corridor();
  const std::vector<WorldTriangle> tris = scenegen_test::world_triangles(scene);
  std::vector<WorldTriangle> occluders;
  for (const WorldTriangle& t : tris)
    if (t.node != "alcove_lamp") occluders.push_back(t);

  const auto lamp = samples(tris, 0.2f, [](const std::string& n) { return n == "alcove_lamp"; });
  const auto surfaces = samples(tris, 0.35f, [](const std::string& n) { return n != "alcove_lamp"; });
  const auto corridor_floor = samples(tris, 0.25f, [](const std::string& n) { return n == "corridor_floor"; });
  ASSERT_GE(lamp.size(), 8u);
  ASSERT_GE(corridor_floor.size(), 100u);

  // Surface points lit directly by the lamp.
  std::vector<SurfacePoint> lit;
  for (const SurfacePoint& s : surfaces)
    if (std::any_of(lamp.begin(), lamp.end(), [&](const SurfacePoint& l) { return visible(s, l, occluders); }))
      lit.push_back(s);
  // The lamp must light something (else the check below proves nothing), all of it inside the alcove.
  ASSERT_GE(lit.size(), 50u);
  for (const SurfacePoint& s : lit) EXPECT_TRUE(s.node == "alcove" || s.node == "alcove_floor") << s.node;

  // And the room must see the lit alcove through its opening (the light does get out).
  const auto room_floor = samples(tris, 0.5f, [](const std::string& n) { return n == "room_floor"; });
  EXPECT_TRUE(std::any_of(room_floor.begin(), room_floor.end(), [&](const SurfacePoint& r) {
    return std::any_of(lit.begin(), lit.end(), [&](const SurfacePoint& s) { return visible(r, s, occluders); });
  }));

  int sees_lamp = 0, sees_lit = 0;
  for (const SurfacePoint& f : corridor_floor) {
    for (const SurfacePoint& l : lamp)
      if (visible(f, l, occluders)) {
        ++sees_lamp;
        break;
      }
    for (const SurfacePoint& s : lit)
      if (visible(f, s, occluders)) {
        ++sees_lit;
        break;
      }
  }
  EXPECT_EQ(sees_lamp, 0) << "corridor floor points with a direct path to the lamp";
  EXPECT_EQ(sees_lit, 0) << "corridor floor points with a one-bounce path from the lamp";
}

}  // namespace

namespace {

// The door is the antiradiance region (gi.region "deforming") and is hinged at its node's
// origin about local +y: rotated back to 0 degrees it fills the doorway (x = 6, z in
// [4.4, 5.4]) up to the 1 cm gaps at the jambs, whatever angle it was authored at.
TEST(CorridorScene, DoorIsADeformingRegionHingedAtItsOrigin) {
  const engine::SceneAsset scene = scenegen::corridor();
  const auto door =
      std::find_if(scene.nodes.begin(), scene.nodes.end(), [](const engine::Node& n) { return n.name == "door"; });
  ASSERT_NE(door, scene.nodes.end());
  EXPECT_EQ(door->gi.region, engine::GiRegion::Deforming);
  EXPECT_EQ(door->translation, glm::vec3(6.0f, 0.0f, 5.4f));
  // Only a rotation about y: the hinge axis.
  EXPECT_NEAR(door->rotation.x, 0.0f, 1e-6f);
  EXPECT_NEAR(door->rotation.z, 0.0f, 1e-6f);
  ASSERT_GE(door->mesh, 0);
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const engine::Primitive& p : scene.meshes[static_cast<std::size_t>(door->mesh)].primitives)
    for (const glm::vec3& v : p.positions) {
      const glm::vec3 w = v + door->translation;  // closed: rotation 0
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
  EXPECT_NEAR(lo.z, 4.41f, 1e-4f);
  EXPECT_NEAR(hi.z, 5.39f, 1e-4f);
  EXPECT_NEAR(lo.y, 0.0f, 1e-4f);
  EXPECT_NEAR(hi.y, 2.05f, 1e-4f);
  EXPECT_LE(hi.x - lo.x, 0.05f);
}

}  // namespace
