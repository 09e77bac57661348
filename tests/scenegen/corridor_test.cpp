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

std::vector<SurfacePoint> samples(const std::vector<WorldTriangle>& tris, float spacing, bool (*keep)(const std::string&)) {
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
      if (visible(f, l, occluders)) { ++sees_lamp; break; }
    for (const SurfacePoint& s : lit)
      if (visible(f, s, occluders)) { ++sees_lit; break; }
  }
  EXPECT_EQ(sees_lamp, 0) << "corridor floor points with a direct path to the lamp";
  EXPECT_EQ(sees_lit, 0) << "corridor floor points with a one-bounce path from the lamp";
}

}  // namespace
