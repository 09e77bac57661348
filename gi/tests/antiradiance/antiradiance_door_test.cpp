// Antiradiance through a doorway (artest::door_scene): a lit plate, a wall with an opening,
// a door (the deforming region) and a receiver that sees the lit plate only through the
// opening. The hard cases of DESIGN.md §3 are named after themselves.
#include <gtest/gtest.h>

#include <gi/reference.h>

#include <cmath>
#include <cstdio>

#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_texel_gather.h"
#include "antiradiance_scenes.h"

namespace {

gi::AntiradianceSettings door_settings() {
  gi::AntiradianceSettings s;
  s.patch_size_m = 0.25f;
  s.bins_per_side = 8;
  s.iterations = 8;
  return s;
}

struct Solved {
  glm::vec3 receiver{0.0f};  // mean indirect irradiance on the receiver (W/m^2)
  gi::AntiradianceSolveReport report;
};

Solved solve(const artest::DoorScene& s, const gi::AntiradianceSettings& settings) {
  auto region = gi::AntiradianceRegion::create(s.input, settings);
  if (!region) {
    ADD_FAILURE() << region.error().to_string();
    return {};
  }
  Solved out;
  out.report = region->update();
  EXPECT_FALSE(out.report.fell_back);  // the symmetric iteration converges here
  EXPECT_EQ(out.report.output_scale, 1.0f);
  const auto e = region->irradiance();
  out.receiver = artest::instance_mean(region->hierarchy(), s.input, s.receiver, e);
  return out;
}

// A 5 x 5 grid of points on the receiver (facing the opening).
std::vector<gi::SurfacePoint> receiver_points() {
  std::vector<gi::SurfacePoint> pts;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      pts.push_back({glm::vec3(2.2f, -0.4f + 0.2f * static_cast<float>(i), -0.4f + 0.2f * static_cast<float>(j)),
                     glm::vec3(-1, 0, 0)});
  return pts;
}

// Receiver mean indirect irradiance by the reference path tracer (the 5 x 5 points).
glm::vec3 reference_receiver(const artest::DoorScene& s, int spp) {
  const std::vector<gi::SurfacePoint> pts = receiver_points();
  gi::ReferenceSettings rs;
  rs.samples_per_pixel = spp;
  auto ref = gi::reference_irradiance(s.input, pts, rs);
  if (!ref) {
    ADD_FAILURE() << ref.error().to_string();
    return glm::vec3(0.0f);
  }
  glm::dvec3 sum(0.0);
  for (const glm::vec3& v : ref->indirect) sum += glm::dvec3(v);
  return glm::vec3(sum / static_cast<double>(pts.size()));
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Measured (docs/antiradiance.md): open 90 degrees the receiver gets 0.168 W/m^2 (the path
// tracer: 0.169); closed, antiradiance lets 6.8% of it through (the paper's known leaking:
// 64 directional bins and 0.25 m elements cancel the unoccluded light only approximately;
// the truth is 0). Bound: 10%.
TEST(AntiradianceDoor, DoorFullyClosedLeaksAtMostTenPercentOfTheOpenLight) {
  const Solved open = solve(artest::door_scene(90.0f), door_settings());
  const Solved closed = solve(artest::door_scene(0.0f), door_settings());
  std::printf("receiver: open %.5f closed %.5f (leak %.2f%%)\n", double(open.receiver.x), double(closed.receiver.x),
              100.0 * double(closed.receiver.x / open.receiver.x));
  ASSERT_GT(open.receiver.x, 0.01f);
  EXPECT_LE(std::abs(closed.receiver.x), 0.10f * open.receiver.x);
  EXPECT_TRUE(finite(closed.receiver));
}

// Open 90 degrees, against the reference path tracer (indirect irradiance, 5 x 5 points).
TEST(AntiradianceDoor, DoorOpenAgreesWithThePathTracerWithinTwentyPercent) {
  const artest::DoorScene scene = artest::door_scene(90.0f);
  const Solved open = solve(scene, door_settings());
  const glm::vec3 ref = reference_receiver(scene, 1024);
  std::printf("receiver open: antiradiance %.5f reference %.5f\n", double(open.receiver.x), double(ref.x));
  ASSERT_GT(ref.x, 0.0f);
  EXPECT_NEAR(open.receiver.x / ref.x, 1.0f, 0.2f);
}

// Mean indirect irradiance gathered at the receiver's 5 x 5 points from the solved hierarchy
// (antiradiance_texel_gather.h), as the output at atlas texels does.
glm::vec3 gathered_receiver(const artest::DoorScene& s) {
  auto region = gi::AntiradianceRegion::create(s.input, door_settings());
  if (!region) {
    ADD_FAILURE() << region.error().to_string();
    return glm::vec3(0.0f);
  }
  region->update();
  std::vector<gi::GatherPoint> points;
  for (const gi::SurfacePoint& p : receiver_points()) points.push_back({p.position_m, p.normal});
  const auto e =
      gi::gather_at_points(region->hierarchy(), region->bins(), region->settings(), region->exitant(), points);
  glm::dvec3 sum(0.0);
  for (const glm::vec3& v : e) sum += glm::dvec3(v);
  return glm::vec3(sum / static_cast<double>(e.size()));
}

// The gather at points reads the same solution as the leaves: open 90 degrees it agrees with
// the path tracer within 20% at the receiver's points, and the closed door blocks what it
// gathers as it blocks the leaves' light (at most 12% of open).
TEST(AntiradianceDoor, GatherAtPointsAgreesWithThePathTracerAndTheDoorBlocksIt) {
  const artest::DoorScene open_scene = artest::door_scene(90.0f);
  const glm::vec3 open = gathered_receiver(open_scene);
  const glm::vec3 closed = gathered_receiver(artest::door_scene(0.0f));
  const glm::vec3 ref = reference_receiver(open_scene, 1024);
  std::printf("gathered at the receiver's points: open %.5f (reference %.5f), closed %.5f (%.1f%% of open)\n",
              double(open.x), double(ref.x), double(closed.x), 100.0 * double(closed.x / open.x));
  ASSERT_GT(ref.x, 0.0f);
  EXPECT_NEAR(open.x / ref.x, 1.0f, 0.2f);
  EXPECT_LE(std::abs(closed.x), 0.12f * open.x);
}

// The door closed flush against the jambs (no gap: its faces touch the wall's): the
// regularized near-field form factor keeps it finite and it still blocks (measured: 6.8%
// through; with a 1 cm gap all round, 9.6%).
TEST(AntiradianceDoor, DoorTouchingTheWallStaysFiniteAndBlocks) {
  const Solved open = solve(artest::door_scene(90.0f, 0.2f, 0.0f), door_settings());
  const Solved touching = solve(artest::door_scene(0.0f, 0.2f, 0.0f), door_settings());
  const Solved gap = solve(artest::door_scene(0.0f, 0.2f, 0.01f), door_settings());
  EXPECT_TRUE(finite(touching.receiver));
  EXPECT_LE(std::abs(touching.receiver.x), 0.10f * open.receiver.x);
  EXPECT_LE(std::abs(gap.receiver.x), 0.12f * open.receiver.x);
}

// A 1 cm wall and a 1 cm door: antiradiance needs no thickness (the front face's J
// cancels). Measured: 6.9% through.
TEST(AntiradianceDoor, VeryThinWallStillBlocks) {
  const Solved open = solve(artest::door_scene(90.0f, 0.01f), door_settings());
  const Solved closed = solve(artest::door_scene(0.0f, 0.01f), door_settings());
  std::printf("thin wall: open %.5f closed %.5f\n", double(open.receiver.x), double(closed.receiver.x));
  EXPECT_TRUE(finite(closed.receiver));
  EXPECT_LE(std::abs(closed.receiver.x), 0.08f * open.receiver.x);
}

// A point light (1 W/sr, 4 pi W) inside the closed door panel, whose faces point outwards:
// finite everywhere, and the light the elements receive, directly and indirectly, is
// bounded by the emitted flux. (The only direct light that escapes the panel grazes the
// jambs its side faces touch: a coplanar contact the shadow rays cannot resolve.)
TEST(AntiradianceDoor, LightInsideTheRegionStaysFiniteAndBoundedByTheEmittedFlux) {
  const artest::DoorScene scene = artest::door_scene(0.0f, 0.2f, 0.0f, true);
  auto region = gi::AntiradianceRegion::create(scene.input, door_settings());
  ASSERT_TRUE(region) << region.error().to_string();
  region->update();
  const auto e = region->irradiance();
  double direct_flux = 0.0, indirect_flux = 0.0;
  const auto& h = region->hierarchy();
  for (std::size_t l = 0; l < h.leaf_count(); ++l) {
    const gi::ElementNode& n = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    ASSERT_TRUE(finite(e[l])) << l;
    direct_flux += static_cast<double>(n.area_m2 * region->direct()[l].x);
    indirect_flux += static_cast<double>(n.area_m2 * std::abs(e[l].x));
  }
  const double emitted = 4.0 * 3.14159265358979;
  std::printf("light inside: direct flux %.4f W, indirect %.4f W of %.3f W emitted\n", direct_flux, indirect_flux,
              emitted);
  EXPECT_LE(direct_flux, emitted);
  EXPECT_LE(indirect_flux, emitted);
  EXPECT_TRUE(finite(artest::instance_mean(h, scene.input, scene.receiver, e)));
}

}  // namespace
