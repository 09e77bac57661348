// The cube-map math of the reflection probes (reflection_probes/probe_cube.h): directions
// and texels agree with OpenGL's cube-map convention, texel solid angles cover the sphere,
// the box projection's parallax, and the GGX prefilter's mean conservation.
#include "reflection_probes/probe_cube.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace {

TEST(ProbeCube, TexelDirectionsRoundTripThroughTheCubeCoordinate) {
  const int s = 8;
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < s; ++y)
      for (int x = 0; x < s; ++x) {
        const glm::vec3 d = gi::cube_texel_direction(face, x, y, s);
        const gi::CubeCoordinate c = gi::cube_coordinate(d);
        EXPECT_EQ(c.face, face);
        EXPECT_NEAR(c.u, (2.0f * static_cast<float>(x) + 1.0f) / s - 1.0f, 1e-5f);
        EXPECT_NEAR(c.v, (2.0f * static_cast<float>(y) + 1.0f) / s - 1.0f, 1e-5f);
      }
}

// OpenGL 4.6 §8.13, table 8.19: the major axis picks the face; e.g. +Y's t grows with +z.
TEST(ProbeCube, FacesFollowOpenGlsTable) {
  EXPECT_EQ(gi::cube_coordinate({1, 0.1f, 0.2f}).face, 0);
  EXPECT_EQ(gi::cube_coordinate({-1, 0.1f, 0.2f}).face, 1);
  EXPECT_EQ(gi::cube_coordinate({0.1f, 1, 0.2f}).face, 2);
  EXPECT_EQ(gi::cube_coordinate({0.1f, -1, 0.2f}).face, 3);
  EXPECT_EQ(gi::cube_coordinate({0.1f, 0.2f, 1}).face, 4);
  EXPECT_EQ(gi::cube_coordinate({0.1f, 0.2f, -1}).face, 5);
  const gi::CubeCoordinate px = gi::cube_coordinate({1.0f, -0.5f, -0.25f});  // sc = -rz, tc = -ry
  EXPECT_FLOAT_EQ(px.u, 0.25f);
  EXPECT_FLOAT_EQ(px.v, 0.5f);
  const gi::CubeCoordinate py = gi::cube_coordinate({0.5f, 1.0f, 0.25f});  // sc = rx, tc = rz
  EXPECT_FLOAT_EQ(py.u, 0.5f);
  EXPECT_FLOAT_EQ(py.v, 0.25f);
}

TEST(ProbeCube, TexelSolidAnglesCoverTheSphere) {
  const int s = 16;
  double sum = 0.0;
  for (int y = 0; y < s; ++y)
    for (int x = 0; x < s; ++x) sum += 6.0 * static_cast<double>(gi::cube_texel_solid_angle(x, y, s));
  EXPECT_NEAR(sum, 4.0 * std::numbers::pi, 1e-4);
}

TEST(ProbeCube, BoxProjectionFromTheCentreIsTheReflectionItself) {
  const glm::vec3 r = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  const glm::vec3 d = gi::box_projected_direction({0, 0, 0}, r, {0, 0, 0}, {-2, -1, -3}, {2, 1, 3});
  EXPECT_NEAR(glm::length(d - r), 0.0f, 1e-6f);
}

// A point 1 m right of the centre of a 4 m cube looking along +z: the ray leaves the box at
// (1, 0, 2), which the probe at the centre sees along normalize(1, 0, 2), not along +z.
TEST(ProbeCube, BoxProjectionAddsTheParallaxOfTheBox) {
  const glm::vec3 d = gi::box_projected_direction({1, 0, 0}, {0, 0, 1}, {0, 0, 0}, {-2, -2, -2}, {2, 2, 2});
  const glm::vec3 expected = glm::normalize(glm::vec3(1, 0, 2));
  EXPECT_NEAR(glm::length(d - expected), 0.0f, 1e-6f);
  // A probe off the box's centre: from (0, 0, -1) the exit point (1, 0, 2) lies along (1, 0, 3).
  const glm::vec3 off = gi::box_projected_direction({1, 0, 0}, {0, 0, 1}, {0, 0, -1}, {-2, -2, -2}, {2, 2, 2});
  EXPECT_NEAR(glm::length(off - glm::normalize(glm::vec3(1, 0, 3))), 0.0f, 1e-6f);
  // From (0, 1, 0) up the diagonal (1, 1, 0): the ceiling y = 2 comes first, at (1, 2, 0).
  const glm::vec3 diag =
      gi::box_projected_direction({0, 1, 0}, glm::normalize(glm::vec3(1, 1, 0)), {0, 0, 0}, {-2, -2, -2}, {2, 2, 2});
  EXPECT_NEAR(glm::length(diag - glm::normalize(glm::vec3(1, 2, 0))), 0.0f, 1e-6f);
}

TEST(ProbeCube, PrefilterKeepsAConstantMapConstantAtEveryLevel) {
  gi::ProbeCube cube = gi::make_probe_cube(16, gi::full_mip_count(16));
  ASSERT_EQ(cube.levels.size(), 5u);
  for (glm::vec3& t : cube.levels[0]) t = glm::vec3(0.25f, 1.5f, 3.0f);
  gi::prefilter_ggx(cube, 64);
  for (std::size_t m = 0; m < cube.levels.size(); ++m) {
    ASSERT_EQ(cube.levels[m].size(), static_cast<std::size_t>(6 * gi::cube_level_size(16, static_cast<int>(m)) *
                                                              gi::cube_level_size(16, static_cast<int>(m))));
    for (const glm::vec3& t : cube.levels[m]) {
      EXPECT_NEAR(t.x, 0.25f, 1e-6f) << "level " << m;
      EXPECT_NEAR(t.y, 1.5f, 1e-5f) << "level " << m;
      EXPECT_NEAR(t.z, 3.0f, 1e-5f) << "level " << m;
    }
  }
}

// The prefilter conserves the map's mean: one bright face's light spreads over the sphere at
// rough levels but its solid-angle-weighted mean stays within a few percent, and the
// roughest level is nearly uniform.
TEST(ProbeCube, PrefilterConservesTheMeanOfAVaryingMap) {
  const int s = 16;
  gi::ProbeCube cube = gi::make_probe_cube(s, gi::full_mip_count(s));
  for (int y = 0; y < s; ++y)
    for (int x = 0; x < s; ++x) cube.levels[0][gi::cube_texel_index(2, x, y, s)] = glm::vec3(6.0f);  // +Y bright
  gi::prefilter_ggx(cube, 256);
  const auto mean = [&](std::size_t m) {
    const int sm = gi::cube_level_size(s, static_cast<int>(m));
    double sum = 0.0;
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < sm; ++y)
        for (int x = 0; x < sm; ++x)
          sum += static_cast<double>(cube.levels[m][gi::cube_texel_index(f, x, y, sm)].x *
                                     gi::cube_texel_solid_angle(x, y, sm));
    return sum / (4.0 * std::numbers::pi);
  };
  const double base = mean(0);
  EXPECT_NEAR(base, 1.0, 1e-4);  // one face of six
  for (std::size_t m = 1; m < cube.levels.size(); ++m) EXPECT_NEAR(mean(m), base, 0.1 * base) << "level " << m;
  // Mirror-like level 1 keeps the face bright and the opposite face dark.
  EXPECT_GT(cube.levels[1][gi::cube_texel_index(2, 4, 4, 8)].x, 5.0f);
  EXPECT_LT(cube.levels[1][gi::cube_texel_index(3, 4, 4, 8)].x, 0.01f);
}

}  // namespace

// The sweep's stand-in for the renderer's textureLod: at a texel's centre it is the texel,
// half-way between two texels their mean, and between levels the linear blend.
TEST(ProbeCube, TrilinearLookupReadsTexelCentresAndBlendsBetweenThem) {
  gi::ProbeCube cube = gi::make_probe_cube(4, 3);
  for (std::size_t i = 0; i < cube.levels[0].size(); ++i) cube.levels[0][i] = glm::vec3(static_cast<float>(i));
  for (glm::vec3& t : cube.levels[1]) t = glm::vec3(100.0f);
  const glm::vec3 centre = gi::cube_texel_direction(4, 1, 2, 4);  // face +Z, texel (1, 2)
  EXPECT_FLOAT_EQ(gi::cube_lookup_trilinear(cube, 0.0f, centre).x, cube.levels[0][gi::cube_texel_index(4, 1, 2, 4)].x);
  // u = 0 lies half-way between texels 1 and 2 of row 2.
  const glm::vec3 between = gi::cube_direction(4, 0.0f, 0.25f);
  EXPECT_FLOAT_EQ(
      gi::cube_lookup_trilinear(cube, 0.0f, between).x,
      0.5f * (cube.levels[0][gi::cube_texel_index(4, 1, 2, 4)].x + cube.levels[0][gi::cube_texel_index(4, 2, 2, 4)].x));
  const float level0 = cube.levels[0][gi::cube_texel_index(4, 1, 2, 4)].x;
  EXPECT_FLOAT_EQ(gi::cube_lookup_trilinear(cube, 0.25f, centre).x, 0.75f * level0 + 0.25f * 100.0f);
  // Past the last level the last level is read.
  EXPECT_FLOAT_EQ(gi::cube_lookup_trilinear(cube, 7.0f, centre).x, 0.0f);
}

namespace {

// A hall [-2, 5] x [0, 3] x [-2, 2] m seen from a probe at (0, 1.5, 0) whose box is only its
// first part, x <= 2: the distance from o along unit d to the hall's walls.
const glm::vec3 kHallMin(-2.0f, 0.0f, -2.0f), kHallMax(5.0f, 3.0f, 2.0f), kBoxMax(2.0f, 3.0f, 2.0f);
const glm::vec3 kHallProbe(0.0f, 1.5f, 0.0f);
float hall_distance(const glm::vec3& o, const glm::vec3& d) {
  float t = 1e30f;
  for (int a = 0; a < 3; ++a)
    if (d[a] != 0.0f) t = std::min(t, ((d[a] > 0.0f ? kHallMax[a] : kHallMin[a]) - o[a]) / d[a]);
  return t;
}

gi::ProbeCube hall_cube(int size) {
  gi::ProbeCube cube = gi::make_probe_cube(size, 1);
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        cube.distance[gi::cube_texel_index(f, x, y, size)] =
            hall_distance(kHallProbe, gi::cube_texel_direction(f, x, y, size));
  return cube;
}

float degrees_between(const glm::vec3& a, const glm::vec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f)) * 180.0f /
         std::numbers::pi_v<float>;
}

}  // namespace

// Floor points seen from an eye in the hall: the search along the reflected ray finds the
// direction, from the probe, of where that ray meets the hall (its far wall beyond the box,
// its ceiling, its side walls) within a degree, where the box alone is off by up to tens of
// degrees beyond the box's open side.
TEST(ProbeCube, TheDistanceSearchFindsWhereTheReflectedRayMeetsTheCapturedHall) {
  const gi::ProbeCube cube = hall_cube(64);
  const glm::vec3 eye(-1.5f, 1.5f, 0.0f);
  float worst = 0.0f, worst_box = 0.0f;
  for (float x : {-1.5f, -1.0f, -0.2f, 0.5f, 0.8f, 1.0f, 1.5f, 1.9f})
    for (float z : {0.0f, 0.7f, -1.5f}) {
      const glm::vec3 p(x, 0.0f, z);
      const glm::vec3 r = glm::reflect(glm::normalize(p - eye), glm::vec3(0.0f, 1.0f, 0.0f));
      const glm::vec3 truth = p + hall_distance(p, r) * r - kHallProbe;
      const glm::vec3 got = gi::distance_corrected_direction(cube, p, r, kHallProbe, kHallMin, kBoxMax);
      worst = std::max(worst, degrees_between(got, truth));
      worst_box =
          std::max(worst_box, degrees_between(gi::box_projected_direction(p, r, kHallProbe, kHallMin, kBoxMax), truth));
      EXPECT_LT(degrees_between(got, truth), 1.0f) << "floor point " << x << ", " << z;
    }
  EXPECT_GT(worst_box, 10.0f);  // what the search is for
  EXPECT_LT(worst, 1.0f);
}

// A point the probe does not see (behind the surface it captured in that direction) gets the
// box's answer; a cube without distances too.
TEST(ProbeCube, APointHiddenFromTheProbeFallsBackToTheBox) {
  gi::ProbeCube cube = gi::make_probe_cube(16, 1);
  cube.distance.assign(cube.levels[0].size(), 0.5f);  // a 0.5 m sphere around the probe
  const glm::vec3 p(1.0f, 0.2f, 0.3f), r = glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f));
  const glm::vec3 boxed = gi::box_projected_direction(p, r, kHallProbe, kHallMin, kBoxMax);
  EXPECT_LT(degrees_between(gi::distance_corrected_direction(cube, p, r, kHallProbe, kHallMin, kBoxMax), boxed), 1e-3f);
  cube.distance.clear();
  EXPECT_LT(degrees_between(gi::distance_corrected_direction(cube, p, r, kHallProbe, kHallMin, kBoxMax), boxed), 1e-3f);
}

namespace {

// The demo level's corridor: [3, 5] x [0, 3] x [8, 16.2] m, closed but for a 1.6 x 2.4 m
// opening (x 3.2-4.8) in its far wall at z = 16.2 into a dark room [0, 8] x [0, 3.5] x
// [16.2, 22.4]; its probe's box reaches z = 16.4 (the far wall's thickness, as placed), the
// probe in the middle 1.5 m up. The distance from o (in the corridor) along unit d to what it meets.
const glm::vec3 kCorridorMin(3.0f, 0.0f, 8.0f), kCorridorMax(5.0f, 3.0f, 16.2f), kCorridorBoxMax(5.0f, 3.0f, 16.4f);
const glm::vec3 kRoomMin(0.0f, 0.0f, 16.2f), kRoomMax(8.0f, 3.5f, 22.4f), kCorridorProbe(4.0f, 1.5f, 12.2f);
float box_distance(const glm::vec3& o, const glm::vec3& d, const glm::vec3& lo, const glm::vec3& hi) {
  float t = 1e30f;
  for (int a = 0; a < 3; ++a)
    if (d[a] != 0.0f) t = std::min(t, ((d[a] > 0.0f ? hi[a] : lo[a]) - o[a]) / d[a]);
  return t;
}
float corridor_distance(const glm::vec3& o, const glm::vec3& d) {
  const float t = box_distance(o, d, kCorridorMin, kCorridorMax);
  const glm::vec3 q = o + t * d;
  const bool through = d.z > 0.0f && q.z > kCorridorMax.z - 1e-4f && q.x > 3.2f && q.x < 4.8f && q.y < 2.4f;
  return through ? t + box_distance(q, d, kRoomMin, kRoomMax) : t;
}

// Its distances as the bake captures them: the mean of 2 x 2 rays per texel.
gi::ProbeCube corridor_cube(int size) {
  gi::ProbeCube cube = gi::make_probe_cube(size, 1);
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        float sum = 0.0f;
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            const float u = (static_cast<float>(x) + 0.25f + 0.5f * static_cast<float>(i)) / size * 2.0f - 1.0f;
            const float v = (static_cast<float>(y) + 0.25f + 0.5f * static_cast<float>(j)) / size * 2.0f - 1.0f;
            sum += corridor_distance(kCorridorProbe, gi::cube_direction(f, u, v));
          }
        cube.distance[gi::cube_texel_index(f, x, y, size)] = 0.25f * sum;
      }
  return cube;
}

}  // namespace

// The demo corridor's floor seen from its hub (cos theta_v 0.1-0.3): near the side walls the
// reflected rays meet the walls' lower parts at grazing angles. The probe saw those walls at
// its box's sides, so the lookup takes the box's answer, the rays' own hits; the search alone,
// on the 32^2 capture's mean, bilinearly read distances, stops on phantom surfaces where the
// wall's and the far room's distances meet, off by 15-16 degrees from z = 13 m on
// (docs/reflection_probes.md, "The box first"). Near the far wall's 0.2 m jambs the box's side
// lies 0.2 m behind the jamb (1.1-1.2 degrees).
TEST(ProbeCube, TheBoxFirstFindsTheCorridorsWallsWhereTheSearchAloneMissesThem) {
  const gi::ProbeCube cube = corridor_cube(32);
  const glm::vec3 eye(4.0f, 1.7f, 1.0f);
  float worst_wall = 0.0f, worst_wall_search = 0.0f, sum = 0.0f, sum_search = 0.0f;
  int count = 0;
  for (float x : {3.1f, 3.25f, 3.5f, 4.0f, 4.5f, 4.75f, 4.9f})
    for (float z : {9.0f, 10.0f, 12.0f, 13.0f, 14.0f, 15.0f, 15.5f, 16.0f}) {
      const glm::vec3 p(x, 0.0f, z);
      const glm::vec3 r = glm::reflect(glm::normalize(p - eye), glm::vec3(0.0f, 1.0f, 0.0f));
      const glm::vec3 truth = p + corridor_distance(p, r) * r - kCorridorProbe;
      const float got = degrees_between(
          gi::distance_corrected_direction(cube, p, r, kCorridorProbe, kCorridorMin, kCorridorBoxMax), truth);
      const float searched = degrees_between(
          gi::distance_corrected_direction(cube, p, r, kCorridorProbe, kCorridorMin, kCorridorBoxMax, -1.0f), truth);
      if (std::abs(x - 4.0f) >= 0.75f && z <= 14.0f) {  // the rays that meet a side wall
        worst_wall = std::max(worst_wall, got), worst_wall_search = std::max(worst_wall_search, searched);
        EXPECT_LT(got, 1.2f) << "floor point " << x << ", " << z;
      }
      sum += got, sum_search += searched, ++count;
    }
  EXPECT_GT(worst_wall_search, 10.0f);  // what the box first is for
  EXPECT_LT(sum, 0.6f * sum_search);    // over the whole floor, openings and jambs included
  std::printf("corridor floor: by the side walls worst %.2f deg (the search alone %.2f), everywhere mean %.2f (%.2f)\n",
              static_cast<double>(worst_wall), static_cast<double>(worst_wall_search),
              static_cast<double>(sum / static_cast<float>(count)),
              static_cast<double>(sum_search / static_cast<float>(count)));
}

// The same corridor, the floor 0.5 m from its side walls at z 9-10.6 m: the reflected rays meet
// the far wall's 0.2 m jambs beside the opening (x 3.0-3.2 and 4.8-5.0 at z = 16.2), which the
// 32^2 capture sees about a texel wide, its mean distances there mixing the jamb's 4 m with
// the dark room's 10 m. Read by the bilinear mean alone, the exit looks like the opening: the
// search goes on through it and stops on the dark room's far wall, 10-11 degrees off (most of
// the demo corridor's inside error, docs/reflection_probes.md, "The opening's rim"). Where the
// exit's texels that saw the side weigh at least half, the box's answer: the jamb. Not all: where
// the mean is within the tolerance of the exit but the ray 10% further on looks through the
// opening (the test that keeps a floor grazed beyond an open side searched), still the opening.
TEST(ProbeCube, AtTheOpeningsRimAThinJambIsTheBoxsSideNotTheOpening) {
  const gi::ProbeCube cube = corridor_cube(32);
  const glm::vec3 eye(4.0f, 1.7f, 1.0f);
  float sum = 0.0f, sum_mean_only = 0.0f, worst_mean_only = 0.0f;
  int jamb_rays = 0, within = 0, within_mean_only = 0;
  for (float x : {3.5f, 4.5f})
    for (float z = 9.0f; z < 10.65f; z += 0.125f) {
      const glm::vec3 p(x, 0.0f, z);
      const glm::vec3 r = glm::reflect(glm::normalize(p - eye), glm::vec3(0.0f, 1.0f, 0.0f));
      const glm::vec3 hit = p + corridor_distance(p, r) * r;
      if (hit.z > 16.25f || std::abs(hit.x - 4.0f) < 0.8f) continue;  // the jambs only
      ++jamb_rays;
      const glm::vec3 truth = hit - kCorridorProbe;
      const float got = degrees_between(
          gi::distance_corrected_direction(cube, p, r, kCorridorProbe, kCorridorMin, kCorridorBoxMax), truth);
      const float mean_only =
          degrees_between(gi::distance_corrected_direction(cube, p, r, kCorridorProbe, kCorridorMin, kCorridorBoxMax,
                                                           gi::kProbeBoxSideTolerance, false),
                          truth);
      sum += got, sum_mean_only += mean_only, worst_mean_only = std::max(worst_mean_only, mean_only);
      within += got < 1.5f ? 1 : 0, within_mean_only += mean_only < 1.5f ? 1 : 0;
    }
  ASSERT_GE(jamb_rays, 20);
  EXPECT_GT(worst_mean_only, 5.0f);  // what the rim's test is for
  EXPECT_GE(within, jamb_rays * 4 / 5);
  EXPECT_LE(within_mean_only, jamb_rays / 2);
  EXPECT_LT(sum, 0.4f * sum_mean_only);
  std::printf("%d rays onto the jambs: %d within 1.5 deg, mean %.2f deg (the bilinear mean alone: %d, %.2f)\n",
              jamb_rays, within, static_cast<double>(sum / static_cast<float>(jamb_rays)), within_mean_only,
              static_cast<double>(sum_mean_only / static_cast<float>(jamb_rays)));
}

// The footprint is the four texels the bilinear read blends: their nearest and farthest bound it.
TEST(ProbeCube, TheDistanceFootprintBoundsTheBilinearRead) {
  const gi::ProbeCube cube = corridor_cube(16);
  for (float a = 0.0f; a < 6.28f; a += 0.37f)
    for (float b = -1.4f; b < 1.5f; b += 0.31f) {
      const glm::vec3 d(std::cos(a) * std::cos(b), std::sin(b), std::sin(a) * std::cos(b));
      const gi::CubeDistanceFootprint f = gi::cube_distance_footprint(cube, d);
      const float mean = gi::cube_distance_bilinear(cube, d);
      EXPECT_LE(f.nearest, mean * 1.0001f);
      EXPECT_GE(f.farthest, mean * 0.9999f);
    }
  EXPECT_EQ(gi::cube_distance_footprint(gi::make_probe_cube(4, 1), glm::vec3(1.0f, 0.0f, 0.0f)).nearest,
            gi::kProbeFarDistance);
}
