// The pairs inside each other's influence (brf_pair_influence): the uniform grid finds
// exactly the pairs a test of every pair finds, at any scale of the influence, for objects of
// two models scattered, scaled and clustered; brf_pair_culling never keeps a pair outside.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>

#include "brf/brf_runtime.h"
#include "brf/brf_visibility.h"
#include "brf_scenes.h"
#include "core/random.h"

namespace {

struct Models {
  gi::BrfMesh cube = brftest::box({0.3f, 0.3f, 0.3f}, 2);
  gi::BrfMesh slab = brftest::box({0.2f, 0.6f, 0.25f}, 2);
  gi::BrfBasis cube_basis = gi::compute_pca_basis(cube, {.lights = 32, .basis = 4}).value();
  gi::BrfBasis slab_basis = gi::compute_pca_basis(slab, {.lights = 32, .basis = 4}).value();
  gi::BasisRadianceField cube_field =
      gi::compute_basis_radiance_field(cube, cube_basis,
                                       {.spheres = 3, .face_resolution = 3, .sh_bands = 3, .directions = 32})
          .value();
  gi::BasisRadianceField slab_field =
      gi::compute_basis_radiance_field(
          slab, slab_basis,
          {.spheres = 3, .face_resolution = 3, .sh_bands = 3, .outer_radius_scale = 3.0f, .directions = 32})
          .value();
};

const Models& models() {
  static const Models m;
  return m;
}

// n objects in a cube of side `extent` (a few clustered at one spot), uniform scales 0.5-2.
std::vector<gi::BrfObject> scatter(int n, float extent, std::uint64_t seed) {
  const Models& m = models();
  std::vector<gi::BrfObject> objects;
  for (int i = 0; i < n; ++i) {
    gi::Pcg32 rng = gi::Pcg32::for_item(seed, static_cast<std::uint64_t>(i));
    glm::vec3 p(rng.next_float(), rng.next_float(), rng.next_float());
    p = i % 7 == 0 ? glm::vec3(0.5f) + 0.01f * p : p;  // a cluster
    const float scale = 0.5f + 1.5f * rng.next_float();
    const glm::mat4 world = glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), extent * p), 6.0f * rng.next_float(),
                                                   glm::normalize(glm::vec3(1.0f, rng.next_float(), 0.5f))),
                                       glm::vec3(scale));
    objects.push_back(i % 2 == 0 ? gi::BrfObject{&m.cube, &m.cube_basis, &m.cube_field, world, glm::vec3(0.7f)}
                                 : gi::BrfObject{&m.slab, &m.slab_basis, &m.slab_field, world, glm::vec3(0.5f)});
  }
  return objects;
}

// Every pair tested: inside when the receiver's bounding sphere reaches into the source's
// outermost field sphere x scale.
std::vector<std::uint8_t> brute_force(std::span<const gi::BrfObject> objects, float scale) {
  const std::size_t n = objects.size();
  std::vector<std::uint8_t> outside(n * n, 1);
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t r = 0; r < n; ++r) {
      if (s == r) continue;
      const gi::BrfSphere rs =
          gi::brf_bounding_sphere(gi::brf_object_box(*objects[r].mesh), objects[r].object_to_world);
      const glm::vec3 c = glm::vec3(objects[s].object_to_world * glm::vec4(objects[s].field->centre, 1.0f));
      const float reach =
          objects[s].field->outer_radius * glm::length(glm::vec3(objects[s].object_to_world[0])) * scale;
      if (glm::length(rs.centre - c) < reach + rs.radius) outside[s * n + r] = 0;
    }
  return outside;
}

TEST(BrfPairInfluence, TheGridFindsExactlyThePairsEveryPairTestFinds) {
  for (float extent : {3.0f, 20.0f, 200.0f})
    for (float scale : {0.25f, 1.0f, 3.0f}) {
      const auto objects = scatter(60, extent, 11);
      std::size_t candidates = 0;
      const auto grid = gi::brf_pair_influence(objects, scale, &candidates);
      const auto truth = brute_force(objects, scale);
      ASSERT_EQ(grid, truth) << "extent " << extent << ", scale " << scale;
      std::size_t inside = 0;
      for (std::uint8_t o : truth) inside += o == 0;
      EXPECT_EQ(candidates, inside);
      if (extent == 200.0f && scale == 0.25f) {
        EXPECT_LT(inside, 60u * 59u / 4);  // far apart: few pairs
      }
      if (extent == 3.0f && scale == 3.0f) {
        EXPECT_EQ(inside, 60u * 59u);  // all within reach
      }
    }
}

TEST(BrfPairInfluence, NoLimitKeepsEveryPairButTheDiagonal) {
  const auto objects = scatter(9, 100.0f, 3);
  for (float scale : {0.0f, -1.0f, std::nanf(""), std::numeric_limits<float>::infinity()}) {
    std::size_t candidates = 0;
    const auto outside = gi::brf_pair_influence(objects, scale, &candidates);
    EXPECT_EQ(candidates, 72u) << scale;
    for (std::size_t s = 0; s < 9; ++s)
      for (std::size_t r = 0; r < 9; ++r) EXPECT_EQ(outside[s * 9 + r], s == r ? 1 : 0) << scale;
  }
  EXPECT_TRUE(gi::brf_pair_influence({}, 1.0f).empty());
}

TEST(BrfPairInfluence, CullingNeverKeepsAPairOutside) {
  const auto objects = scatter(40, 30.0f, 5);
  std::vector<std::array<std::vector<float>, 3>> weights;
  for (const gi::BrfObject& o : objects) {
    const auto& basis = *o.basis;
    std::vector<glm::vec3> light(o.mesh->positions.size(), glm::vec3(1.0f, 0.5f, 0.25f));
    weights.push_back(gi::brf_fit_rgb(basis, light));
  }
  const auto outside = gi::brf_pair_influence(objects, 1.0f);
  for (float threshold : {0.0f, 1e-3f, 0.1f}) {
    const auto culled = gi::brf_pair_culling(objects, weights, threshold, 1.0f);
    const auto unlimited = gi::brf_pair_culling(objects, weights, threshold, 0.0f);
    std::size_t kept = 0;
    for (std::size_t k = 0; k < culled.size(); ++k) {
      if (outside[k] != 0) {
        EXPECT_NE(culled[k], 0) << k;
      }
      kept += culled[k] == 0;
    }
    if (threshold == 0.0f) {
      EXPECT_EQ(culled, outside);
    }
    std::size_t kept_unlimited = 0;
    for (std::uint8_t c : unlimited) kept_unlimited += c == 0;
    EXPECT_LE(kept, kept_unlimited) << threshold;
    EXPECT_GT(kept, 0u) << threshold;
  }
}

}  // namespace
