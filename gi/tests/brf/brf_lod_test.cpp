// Level of detail for distant pairs (brf_lod.h): the representative points of a crate and
// their weights; the CPU twin with the level of detail off is bit for bit what it was, near
// pairs are untouched, far pairs stay within the documented per-vertex bound; the GPU pass
// with the level of detail on matches its twin (llvmpipe through EGL; fails, never skips).
#include "brf/brf_lod.h"

#include <gtest/gtest.h>
#include <engine/gpu/context.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>

#include "brf/brf_gpu_pass.h"
#include "brf/brf_runtime.h"
#include "brf_scenes.h"
#include "gl_context.h"

namespace {

// A crate (4 x 4 quads a face, 150 vertices) with a small basis and field.
struct Crate {
  gi::BrfMesh mesh = brftest::box(glm::vec3(0.25f), 4);
  gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 64, .basis = 8}).value();
  gi::BasisRadianceField field = gi::compute_basis_radiance_field(
                                     mesh, basis, {.spheres = 6, .face_resolution = 6, .sh_bands = 3, .directions = 64})
                                     .value();
};

const Crate& crate() {
  static const Crate c;
  return c;
}

// n x n crates on the floor 1.2 m apart, each turned a little: neighbours are near (their
// gap 1.8 inner radii), diagonal and farther ones far at lod_distance 2.
std::vector<gi::BrfObject> grid(int side) {
  const Crate& c = crate();
  std::vector<gi::BrfObject> objects;
  for (int i = 0; i < side * side; ++i)
    objects.push_back({&c.mesh, &c.basis, &c.field,
                       glm::rotate(glm::translate(glm::mat4(1.0f), {1.2f * static_cast<float>(i % side), 0.25f,
                                                                    1.2f * static_cast<float>(i / side)}),
                                   0.15f * static_cast<float>(i), glm::vec3(0, 1, 0)),
                       glm::vec3(0.8f, 0.4f + 0.1f * static_cast<float>(i % 3), 0.3f)});
  return objects;
}

// Direct light from a point above the grid plus a little sky, unshadowed.
std::vector<std::vector<glm::vec3>> incoming(std::span<const gi::BrfObject> objects, glm::vec3 light) {
  std::vector<std::vector<glm::vec3>> in;
  for (const gi::BrfObject& o : objects) {
    const gi::BrfWorldVertices v = gi::brf_world_vertices(o);
    auto& e = in.emplace_back();
    for (std::size_t j = 0; j < v.positions.size(); ++j) {
      const glm::vec3 d = light - v.positions[j];
      const float cos_theta = std::max(0.0f, glm::dot(v.normals[j], glm::normalize(d)));
      e.push_back(glm::vec3(1.0f, 0.9f, 0.7f) * (20.0f * cos_theta / glm::dot(d, d)) + glm::vec3(0.02f));
    }
  }
  return in;
}

TEST(BrfLodPoints, CrateFacesGetALatticeOfPointsThatReproducesLinearFunctions) {
  const gi::BrfMesh& mesh = crate().mesh;
  const gi::BrfLodPoints lod = gi::brf_lod_points(mesh);
  ASSERT_EQ(lod.from.size(), mesh.positions.size());
  EXPECT_EQ(lod.points.size(), 24u);  // 6 faces x 2 x 2 (their corners)
  EXPECT_TRUE(std::is_sorted(lod.points.begin(), lod.points.end()));
  const glm::vec3 a(0.3f, -1.2f, 0.7f);
  auto f = [&](const glm::vec3& p) { return glm::dot(a, p) + 0.4f; };
  for (std::size_t j = 0; j < mesh.positions.size(); ++j) {
    const glm::vec3 w = lod.weights[j];
    ASSERT_TRUE(glm::all(glm::lessThan(lod.from[j], glm::uvec3(static_cast<std::uint32_t>(lod.points.size())))));
    const glm::uvec3 r(lod.points[lod.from[j].x], lod.points[lod.from[j].y], lod.points[lod.from[j].z]);
    if (std::binary_search(lod.points.begin(), lod.points.end(), static_cast<std::uint32_t>(j))) {
      EXPECT_EQ(r, glm::uvec3(static_cast<std::uint32_t>(j)));
      EXPECT_EQ(w, glm::vec3(1.0f, 0.0f, 0.0f));
      continue;
    }
    for (int k = 0; k < 3; ++k) {  // from the vertex's own face
      EXPECT_GT(glm::dot(mesh.normals[r[k]], mesh.normals[j]), gi::kBrfLodNormalCos);
      EXPECT_NEAR(glm::dot(mesh.normals[j], mesh.positions[r[k]] - mesh.positions[j]), 0.0f, 1e-5f);
    }
    EXPECT_NEAR(w.x + w.y + w.z, 1.0f, 1e-5f);
    EXPECT_GE(std::min({w.x, w.y, w.z}), -1e-5f) << "vertex " << j << " is interpolated, not extrapolated";
    const float interpolated =
        w.x * f(mesh.positions[r.x]) + w.y * f(mesh.positions[r.y]) + w.z * f(mesh.positions[r.z]);
    EXPECT_NEAR(interpolated, f(mesh.positions[j]), 1e-5f) << "vertex " << j;
  }
}

TEST(BrfLodPoints, SmoothMeshesGetNoTable) {
  // A latitude-longitude sphere: every vertex its own normal, too many groups.
  gi::BrfMesh sphere;
  for (int i = 1; i < 12; ++i)
    for (int k = 0; k < 16; ++k) {
      const float t = std::numbers::pi_v<float> * static_cast<float>(i) / 12.0f;
      const float p = 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / 16.0f;
      const glm::vec3 n(std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p));
      sphere.positions.push_back(0.3f * n);
      sphere.normals.push_back(n);
    }
  EXPECT_TRUE(gi::brf_lod_points(sphere).empty());
}

TEST(BrfLodPoints, PairsAreFarBeyondTheMultipleOfTheInnerSphere) {
  const gi::BrfSphere source{{0.0f, 0.0f, 0.0f}, 0.5f};
  const gi::BrfSphere receiver{{3.0f, 0.0f, 0.0f}, 0.5f};  // gap 2.5 = 5 inner radii
  EXPECT_TRUE(gi::brf_pair_far(receiver, source, 4.9f));
  EXPECT_FALSE(gi::brf_pair_far(receiver, source, 5.1f));
  EXPECT_FALSE(gi::brf_pair_far(receiver, source, 0.0f));
  EXPECT_FALSE(gi::brf_pair_far(receiver, source, std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(gi::brf_pair_far(receiver, source, std::numeric_limits<float>::quiet_NaN()));
}

TEST(BrfLod, OffIsBitIdenticalAndNearPairsAreUnchanged) {
  const std::vector<gi::BrfObject> objects = grid(3);
  const auto in = incoming(objects, {1.2f, 2.5f, 1.0f});
  const gi::BrfResult off = gi::brf_interreflect(objects, in, {.cull_threshold = 0.0f, .lod_distance = 0.0f});
  EXPECT_EQ(off.pairs_lod, 0u);
  // Off by every spelling, and on with no pair far enough: the same bits.
  for (float lod : {0.0f, -1.0f, std::numeric_limits<float>::infinity(), 1e6f}) {
    const gi::BrfResult r = gi::brf_interreflect(objects, in, {.cull_threshold = 0.0f, .lod_distance = lod});
    EXPECT_EQ(r.pairs_lod, 0u) << lod;
    EXPECT_EQ(r.indirect, off.indirect) << lod;
  }
  // Two neighbours (1.8 inner radii apart) at lod_distance 2: near, exact.
  const std::vector<gi::BrfObject> two(objects.begin(), objects.begin() + 2);
  const std::vector<std::vector<glm::vec3>> in_two(in.begin(), in.begin() + 2);
  const gi::BrfResult exact = gi::brf_interreflect(two, in_two, {.cull_threshold = 0.0f, .lod_distance = 0.0f});
  const gi::BrfResult near = gi::brf_interreflect(two, in_two, {.cull_threshold = 0.0f, .lod_distance = 2.0f});
  EXPECT_EQ(near.pairs_lod, 0u);
  EXPECT_EQ(near.indirect, exact.indirect);
}

TEST(BrfLod, FarPairsEvaluateTheRepresentativePointsExactlyAndStayWithinTheBound) {
  const std::vector<gi::BrfObject> objects = grid(3);
  const gi::BrfObject& source = objects[0];
  const gi::BrfObject& receiver = objects[8];  // the opposite corner: 3.4 m, far
  const gi::BrfWorldVertices v = gi::brf_world_vertices(receiver);
  const gi::BrfLodPoints lod = gi::brf_lod_points(*receiver.mesh);
  std::vector<float> full, reduced;
  gi::brf_basis_irradiance(source, v.positions, v.normals, full);
  gi::brf_basis_irradiance(source, v.positions, v.normals, reduced, nullptr, {}, {}, &lod);
  const std::size_t c = static_cast<std::size_t>(source.field->channel_count());
  ASSERT_EQ(full.size(), reduced.size());
  for (std::uint32_t p : lod.points)
    for (std::size_t k = 0; k < c; ++k) EXPECT_EQ(reduced[p * c + k], full[p * c + k]);
  EXPECT_NE(reduced, full);  // the others are interpolated

  // The whole frame: per-vertex error against the exact evaluation, by threshold.
  const auto in = incoming(objects, {1.2f, 2.5f, 1.0f});
  const gi::BrfResult exact = gi::brf_interreflect(objects, in, {.cull_threshold = 0.0f, .lod_distance = 0.0f});
  for (float lod_distance : {3.0f, 5.0f}) {
    const gi::BrfResult r = gi::brf_interreflect(objects, in, {.cull_threshold = 0.0f, .lod_distance = lod_distance});
    const auto [max_rel, p95] = gi::brf_vertex_error(r, exact);
    std::printf("lod_distance %.1f: %zu of %zu pairs far, vertex rel error max %.4f, p95 %.4f\n", double(lod_distance),
                r.pairs_lod, r.pairs_evaluated, max_rel, p95);
    EXPECT_GT(r.pairs_lod, 0u);
    EXPECT_LT(r.pairs_lod, r.pairs_evaluated);  // the neighbours stay exact
    EXPECT_LT(max_rel, 0.05) << lod_distance;   // measured 0.013 at both
    EXPECT_LT(p95, 0.01) << lod_distance;       // measured 0.004
  }
  // Shared visibility: whole rows interpolated (a face partly hidden by the middle crate gets
  // its corners' mix): looser.
  const gi::BrfResult shared =
      gi::brf_interreflect(objects, in, {.cull_threshold = 0.0f, .lod_distance = 5.0f, .lod_shared_visibility = true});
  const auto [max_shared, p95_shared] = gi::brf_vertex_error(shared, exact);
  std::printf("lod_distance 5.0, shared visibility: vertex rel error max %.4f, p95 %.4f\n", max_shared, p95_shared);
  EXPECT_EQ(shared.pairs_lod, 20u);
  EXPECT_LT(max_shared, 0.3);  // measured 0.10, p95 0.033
  EXPECT_LT(p95_shared, 0.1);
}

using gltest::headless_or_fail;

double relative_rmse(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
  double err = 0.0, norm = 0.0;
  for (std::size_t k = 0; k < b.size(); ++k) {
    const glm::dvec3 d = glm::dvec3(a[k]) - glm::dvec3(b[k]);
    err += glm::dot(d, d);
    norm += glm::dot(glm::dvec3(b[k]), glm::dvec3(b[k]));
  }
  return std::sqrt(err / norm);
}

TEST(BrfLod, GpuPassMatchesItsTwinWithTheLevelOfDetail) {
  auto ctx = headless_or_fail();
  const Crate& c = crate();
  const gi::BrfModel model{"", c.mesh, c.basis, c.field};
  auto created = gi::BrfGpuPass::create(std::span(&model, 1));
  ASSERT_TRUE(created.ok()) << created.error().to_string();
  gi::BrfGpuPass pass = std::move(created).value();
  const std::vector<gi::BrfObject> objects = grid(3);
  std::vector<gi::BrfInstance> instances;
  for (const gi::BrfObject& o : objects) instances.push_back({0, o.object_to_world, o.albedo});
  const auto in = incoming(objects, {1.2f, 2.5f, 1.0f});
  auto all = [&] {
    std::vector<glm::vec3> v;
    for (std::size_t i = 0; i < instances.size(); ++i) {
      const auto r = pass.read_back_vertices(i);
      v.insert(v.end(), r.begin(), r.end());
    }
    return v;
  };
  auto flat = [](const gi::BrfResult& r) {
    std::vector<glm::vec3> v;
    for (const auto& o : r.indirect) v.insert(v.end(), o.begin(), o.end());
    return v;
  };
  for (const auto& [cull, shared] : {std::pair{0.0f, false}, std::pair{1e-3f, false}, std::pair{1e-3f, true}}) {
    const gi::BrfUpdateSettings off{.bounces = 3, .cull_threshold = cull, .lod_distance = 0.0f};
    const gi::BrfUpdateSettings on{
        .bounces = 3, .cull_threshold = cull, .lod_distance = 2.0f, .lod_shared_visibility = shared};
    ASSERT_TRUE(pass.run(instances, in, off).ok());
    const std::vector<glm::vec3> gpu_off = all();
    EXPECT_EQ(pass.stats().pairs_lod, 0u);
    ASSERT_TRUE(pass.run(instances, in, on).ok());
    EXPECT_EQ(pass.stats().pairs_reused, pass.stats().pairs_evaluated - pass.stats().pairs_lod)
        << "switching the level of detail on re-evaluates the far pairs only";
    const gi::BrfResult ref = gi::brf_interreflect(objects, in, on);
    const std::vector<glm::vec3> gpu_on = all();
    const double e = relative_rmse(gpu_on, flat(ref));
    std::printf(
        "cull %g, shared visibility %d: lod on, GPU vs CPU rel RMSE %.2e, %zu far pairs of %zu; lod on vs off %.2e\n",
        double(cull), int(shared), e, pass.stats().pairs_lod, pass.stats().pairs_evaluated,
        relative_rmse(gpu_on, gpu_off));
    EXPECT_LT(e, 1e-3);
    EXPECT_GT(ref.pairs_lod, 0u);
    EXPECT_EQ(pass.stats().pairs_lod, ref.pairs_lod);
    EXPECT_EQ(pass.stats().pairs_evaluated, ref.pairs_evaluated);
    EXPECT_GT(relative_rmse(gpu_on, gpu_off), 1e-6) << "the GPU pass used the level of detail";
    // A still frame keeps every pair's Phi, the interpolated ones included.
    ASSERT_TRUE(pass.run(instances, in, on).ok());
    EXPECT_EQ(pass.stats().pairs_reused, pass.stats().pairs_evaluated);
    EXPECT_LT(relative_rmse(all(), flat(ref)), 1e-3);
  }
}

// Kind 0's far-pair representative points packed several pairs to a work group, one
// invocation per point (BrfGpuPassOptions::pack_lod_points, the default), give the per-pair
// work groups' results bit for bit: 4 x 4 crates (16 crates, 24 points each), d = 2, with
// and without shared visibility, one model and two (the instances alternating).
TEST(BrfLod, PackedRepresentativePointsGiveTheSameBitsAsOneWorkGroupPerPair) {
  auto ctx = headless_or_fail();
  const Crate& c = crate();
  const gi::BrfModel model{"", c.mesh, c.basis, c.field};
  const std::vector<gi::BrfModel> models = {model, model};
  const std::vector<gi::BrfObject> objects = grid(4);
  const auto in = incoming(objects, {1.8f, 2.5f, 1.6f});
  for (const std::size_t model_count : {std::size_t{1}, std::size_t{2}}) {
    std::vector<gi::BrfInstance> instances;
    for (std::size_t i = 0; i < objects.size(); ++i)
      instances.push_back({static_cast<std::uint32_t>(i % model_count), objects[i].object_to_world, objects[i].albedo});
    std::vector<glm::vec3> result[2];
    for (const bool shared : {false, true}) {
      std::size_t far = 0;
      for (int packed = 0; packed < 2; ++packed) {
        gi::BrfGpuPassOptions options;
        options.pack_lod_points = packed != 0;
        auto created = gi::BrfGpuPass::create(std::span(models.data(), model_count), options);
        ASSERT_TRUE(created.ok()) << created.error().to_string();
        gi::BrfGpuPass pass = std::move(created).value();
        const gi::BrfUpdateSettings on{
            .bounces = 3, .cull_threshold = 0.0f, .lod_distance = 2.0f, .lod_shared_visibility = shared};
        const auto status = pass.run(instances, in, on);
        ASSERT_TRUE(status.ok()) << status.error().to_string();
        result[packed].clear();
        for (std::size_t i = 0; i < instances.size(); ++i) {
          const auto r = pass.read_back_vertices(i);
          result[packed].insert(result[packed].end(), r.begin(), r.end());
        }
        far = pass.stats().pairs_lod;
        if (packed != 0)
          EXPECT_EQ(pass.stats().lod_points_packed, far * 24u) << "24 points per crate, packed";
        else
          EXPECT_EQ(pass.stats().lod_points_packed, 0u);
      }
      EXPECT_GT(far, 20u);
      ASSERT_EQ(result[0].size(), result[1].size());
      std::size_t differ = 0;
      for (std::size_t k = 0; k < result[0].size(); ++k) differ += result[0][k] != result[1][k] ? 1 : 0;
      EXPECT_EQ(differ, 0u) << model_count << " model(s), shared visibility " << shared;
    }
  }
}

}  // namespace
