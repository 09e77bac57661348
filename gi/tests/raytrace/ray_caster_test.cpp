#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "core/random.h"
#include "raytrace/brute_force_ray_caster.h"
#include "raytrace/embree_ray_caster.h"

namespace {

// A unit cube (two triangles per face) as object-space geometry.
gi::RtGeometry unit_cube() {
  gi::RtGeometry g;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const float sign = face % 2 ? 1.0f : -1.0f;
    const int u = (axis + 1) % 3;
    const int v = (axis + 2) % 3;
    const auto base = static_cast<std::uint32_t>(g.positions.size());
    for (int k = 0; k < 4; ++k) {
      glm::vec3 p(0.0f);
      p[axis] = 0.5f * sign;
      p[u] = (k == 1 || k == 2) ? 0.5f : -0.5f;
      p[v] = (k >= 2) ? 0.5f : -0.5f;
      g.positions.push_back(p);
    }
    g.indices.insert(g.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  return g;
}

gi::RtSceneData scattered_cubes(int count, std::uint64_t seed) {
  gi::RtSceneData data;
  data.geometries.push_back(unit_cube());
  for (int i = 0; i < count; ++i) {
    gi::Pcg32 rng = gi::Pcg32::for_item(seed, static_cast<std::uint64_t>(i));
    glm::mat4 m = glm::translate(
        glm::mat4(1.0f), glm::vec3(rng.next_float() * 8 - 4, rng.next_float() * 8 - 4, rng.next_float() * 8 - 4));
    m = glm::rotate(m, rng.next_float() * 6.28f, glm::normalize(glm::vec3(1, rng.next_float(), 0.3f)));
    m = glm::scale(m, glm::vec3(0.3f + rng.next_float()));
    data.instances.push_back(gi::RtInstance{0, m, i % 3 == 0, static_cast<std::uint64_t>(i)});
  }
  return data;
}

gi::Ray random_ray(gi::Pcg32& rng) {
  gi::Ray r;
  r.origin = glm::vec3(rng.next_float() * 12 - 6, rng.next_float() * 12 - 6, rng.next_float() * 12 - 6);
  const float z = 1 - 2 * rng.next_float();
  const float phi = 2 * std::numbers::pi_v<float> * rng.next_float();
  const float s = std::sqrt(std::max(0.0f, 1 - z * z));
  r.direction = {s * std::cos(phi), s * std::sin(phi), z};
  return r;
}

TEST(EmbreeRayCaster, AgreesWithBruteForceOnIncoherentRays) {
  const gi::RtSceneData data = scattered_cubes(40, 7);
  auto embree = gi::make_embree_ray_caster(data);
  ASSERT_TRUE(embree) << embree.error().to_string();
  gi::BruteForceRayCaster brute(data);
  gi::Pcg32 rng(1, 2);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const gi::Ray r = random_ray(rng);
    const gi::Hit a = (*embree)->intersect(r);
    const gi::Hit b = brute.intersect(r);
    ASSERT_EQ(a.valid(), b.valid()) << "ray " << i;
    EXPECT_EQ((*embree)->occluded(r), b.valid());
    if (!a.valid()) continue;
    ++hits;
    EXPECT_NEAR(a.t, b.t, 1e-4f * (1 + b.t));
    EXPECT_EQ(a.instance, b.instance);
    // Normals from the same world-space triangle, up to the triangle choice on shared edges.
    EXPECT_NEAR(std::abs(glm::dot(glm::normalize(a.geometric_normal), glm::normalize(b.geometric_normal))), 1.0f,
                1e-3f);
  }
  EXPECT_GT(hits, 200);  // the test must exercise hits, not only misses
}

TEST(EmbreeRayCaster, StreamQueriesMatchSingleRays) {
  const gi::RtSceneData data = scattered_cubes(20, 3);
  auto rc = gi::make_embree_ray_caster(data);
  ASSERT_TRUE(rc);
  gi::Pcg32 rng(5, 6);
  std::vector<gi::Ray> rays(500);
  for (gi::Ray& r : rays) r = random_ray(rng);
  std::vector<gi::Hit> hits(rays.size());
  std::vector<std::uint8_t> occ(rays.size());
  (*rc)->intersect_many(rays, hits);
  (*rc)->occluded_many(rays, occ);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const gi::Hit single = (*rc)->intersect(rays[i]);
    EXPECT_EQ(single.valid(), hits[i].valid());
    EXPECT_EQ(single.t, hits[i].t);
    EXPECT_EQ(occ[i] != 0, single.valid());
  }
  // A coherent stream (the flux check's: every ray from one point, neighbouring directions;
  // intersect_many traces it in packets) gives the very hits of single rays: triangle,
  // distance, barycentrics and normal. 1021 rays: the last packet is partial.
  std::vector<gi::Ray> fan;
  for (int i = 0; i < 1021; ++i) {
    const float z = 1.0f - 2.0f * (static_cast<float>(i) + 0.5f) / 1021.0f;
    const float phi = 2.39996323f * static_cast<float>(i);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    fan.push_back(gi::Ray{glm::vec3(0.3f, 0.2f, -0.1f), 0.0f, glm::vec3(r * std::cos(phi), r * std::sin(phi), z)});
  }
  std::vector<gi::Hit> fan_hits(fan.size());
  (*rc)->intersect_many(fan, fan_hits);
  int fan_hit_count = 0;
  for (std::size_t i = 0; i < fan.size(); ++i) {
    const gi::Hit single = (*rc)->intersect(fan[i]);
    ASSERT_EQ(single.valid(), fan_hits[i].valid()) << i;
    if (!single.valid()) continue;
    ++fan_hit_count;
    EXPECT_EQ(single.t, fan_hits[i].t) << i;
    EXPECT_EQ(single.instance, fan_hits[i].instance) << i;
    EXPECT_EQ(single.primitive, fan_hits[i].primitive) << i;
    EXPECT_EQ(single.barycentric, fan_hits[i].barycentric) << i;
    EXPECT_EQ(single.geometric_normal, fan_hits[i].geometric_normal) << i;
  }
  EXPECT_GT(fan_hit_count, 100);  // the fan must hit the cubes, not only miss them
}

TEST(EmbreeRayCaster, CoherentOcclusionMatchesSingleRays) {
  const gi::RtSceneData data = scattered_cubes(20, 3);
  auto rc = gi::make_embree_ray_caster(data);
  ASSERT_TRUE(rc);
  // Shadow rays towards one light (PRM entry points: a segment from each point to the light,
  // t_max 1) and rays in random directions; 1013 of each, so the last packet is partial.
  const glm::vec3 light(0.3f, 0.2f, -0.1f);
  gi::Pcg32 rng(11, 12);
  std::vector<gi::Ray> rays;
  for (int i = 0; i < 1013; ++i) {
    const glm::vec3 p(rng.next_float() * 12 - 6, rng.next_float() * 12 - 6, rng.next_float() * 12 - 6);
    rays.push_back(gi::Ray{p, 0.0f, light - p, 1.0f});
  }
  for (int i = 0; i < 1013; ++i) rays.push_back(random_ray(rng));
  for (const std::size_t n : {rays.size(), std::size_t{1013}, std::size_t{16}, std::size_t{5}, std::size_t{0}}) {
    const std::span<const gi::Ray> some(rays.data(), n);
    std::vector<std::uint8_t> coherent(n, 7), many(n, 7);
    (*rc)->occluded_coherent(some, coherent);
    (*rc)->occluded_many(some, many);
    std::size_t blocked = 0;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(coherent[i], (*rc)->occluded(some[i]) ? 1 : 0) << "ray " << i << " of " << n;
      ASSERT_EQ(coherent[i], many[i]) << "ray " << i << " of " << n;
      blocked += coherent[i];
    }
    if (n >= 1013) {
      EXPECT_GT(blocked, n / 10) << "the rays must be blocked often, not only pass";
      EXPECT_LT(blocked, n - n / 10) << "the rays must pass often, not only be blocked";
    }
  }
  // The interface's default (a caster without packets) answers the same.
  gi::BruteForceRayCaster brute(data);
  std::vector<std::uint8_t> coherent(rays.size());
  brute.occluded_coherent(rays, coherent);
  for (std::size_t i = 0; i < rays.size(); ++i) ASSERT_EQ(coherent[i], brute.occluded(rays[i]) ? 1 : 0) << i;
}

TEST(EmbreeRayCaster, MovingDynamicInstanceUpdatesHits) {
  gi::RtSceneData data;
  data.geometries.push_back(unit_cube());
  data.instances.push_back(gi::RtInstance{0, glm::mat4(1.0f), true, 0});
  auto rc = gi::make_embree_ray_caster(data);
  ASSERT_TRUE(rc);
  const gi::Ray down{.origin = {0, 5, 0}, .direction = {0, -1, 0}};
  EXPECT_NEAR((*rc)->intersect(down).t, 4.5f, 1e-5f);
  (*rc)->set_instance_transform(0, glm::translate(glm::mat4(1.0f), glm::vec3(0, 2, 0)));
  (*rc)->commit();
  const gi::Hit h = (*rc)->intersect(down);
  EXPECT_NEAR(h.t, 2.5f, 1e-5f);
  EXPECT_GT(glm::normalize(h.geometric_normal).y, 0.99f);  // top face, outward winding
  (*rc)->set_instance_transform(0, glm::translate(glm::mat4(1.0f), glm::vec3(10, 0, 0)));
  (*rc)->commit();
  EXPECT_FALSE((*rc)->intersect(down).valid());
}

TEST(EmbreeRayCaster, RespectsRayInterval) {
  gi::RtSceneData data;
  data.geometries.push_back(unit_cube());
  data.instances.push_back(gi::RtInstance{0, glm::mat4(1.0f), false, 0});
  auto rc = gi::make_embree_ray_caster(data);
  ASSERT_TRUE(rc);
  EXPECT_FALSE((*rc)->occluded(gi::Ray{.origin = {0, 5, 0}, .direction = {0, -1, 0}, .t_max = 4.4f}));
  EXPECT_TRUE((*rc)->occluded(gi::Ray{.origin = {0, 5, 0}, .direction = {0, -1, 0}, .t_max = 4.6f}));
  EXPECT_FALSE((*rc)->occluded(gi::Ray{.origin = {0, 5, 0}, .t_min = 0.0f, .direction = {0, 1, 0}}));
}

TEST(EmbreeRayCaster, RejectsBadGeometryWithAClearError) {
  gi::RtSceneData data;
  data.geometries.push_back(unit_cube());
  data.geometries[0].indices.push_back(999);
  data.geometries[0].indices.push_back(0);
  data.geometries[0].indices.push_back(1);
  data.instances.push_back(gi::RtInstance{0, glm::mat4(1.0f), false, 0});
  auto rc = gi::make_embree_ray_caster(data);
  ASSERT_FALSE(rc);
  EXPECT_NE(rc.error().to_string().find("index 999 out of range"), std::string::npos);

  gi::RtSceneData nan_data;
  nan_data.geometries.push_back(unit_cube());
  glm::mat4 m(1.0f);
  m[3][0] = std::nanf("");
  nan_data.instances.push_back(gi::RtInstance{0, m, false, 0});
  auto rc2 = gi::make_embree_ray_caster(nan_data);
  ASSERT_FALSE(rc2);
  EXPECT_NE(rc2.error().to_string().find("non-finite transform"), std::string::npos);
}

}  // namespace
