// The basis-radiance-field interreflection on the GPU (llvmpipe through EGL; fails, never
// skips, without a context) against its CPU twin gi::brf_interreflect: the same pairs, the
// same bounces, the same static receivers, relative RMSE below 1e-3 (float32 on both sides;
// the GPU fits sum in float where the CPU sums in double). Phi caching: moving one object
// re-evaluates only its pairs, a still frame none. Glossy objects: brf_gpu_glossy_test.cpp;
// the shared scenes and measures: brf_gpu_fixtures.h.
#include "brf/brf_gpu_pass.h"

#include <gtest/gtest.h>
#include <engine/gpu/context.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>

#include "brf/brf_runtime.h"
#include "brf_gpu_fixtures.h"
#include "brf_scenes.h"
#include "gl_context.h"

namespace {

using namespace brfgpu;
using gltest::headless_or_fail;

TEST(BrfGpuPass, MatchesCpuTwinWithoutCullingWithStaticReceivers) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  const StaticPoints floor = static_points();
  ASSERT_TRUE(pass.set_static_receivers(floor.positions, floor.normals).ok());
  const auto instances = three_objects();
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f};
  const auto status = pass.run(instances, incoming, settings);
  ASSERT_TRUE(status.ok()) << status.error().to_string();
  const gi::BrfResult ref = cpu(instances, incoming, settings, &floor);

  const double e = vertices_error(pass, ref);
  double static_norm = 0.0;
  const auto st = pass.read_back_static();
  const double es = relative_rmse(st, ref.static_irradiance, &static_norm);
  std::printf("no culling: vertices rel RMSE %.2e, static rel RMSE %.2e, %zu bytes on the GPU\n", e, es,
              pass.gpu_bytes());
  EXPECT_LT(e, kTolerance);
  EXPECT_GT(static_norm, 0.0);
  EXPECT_LT(es, kTolerance);
  EXPECT_EQ(st[st.size() - 1], glm::vec3(0.0f));  // outside every field
  EXPECT_EQ(st[st.size() - 2], glm::vec3(0.0f));
  EXPECT_EQ(pass.stats().pairs_evaluated, ref.pairs_evaluated);
  EXPECT_EQ(pass.stats().pairs_evaluated, 6u);
  EXPECT_EQ(pass.stats().pairs_culled, 0u);
  EXPECT_EQ(pass.stats().pairs_reused, 0u);
  EXPECT_EQ(pass.stats().static_sources_reused, 0u);
  EXPECT_GT(pass.gpu_bytes(), models().cube_field.bytes() + models().slab_field.bytes());
}

TEST(BrfGpuPass, MatchesCpuTwinWithCulling) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  const auto instances = three_objects(3.0f);  // the third object far away: its pairs are culled
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  for (int bounces : {1, 2, 3}) {
    const gi::BrfUpdateSettings settings{.bounces = bounces, .cull_threshold = 0.05f};
    ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
    const gi::BrfResult ref = cpu(instances, incoming, settings);
    const double e = vertices_error(pass, ref);
    std::printf("culling, %d bounces: rel RMSE %.2e, %zu pairs evaluated, %zu culled\n", bounces, e,
                pass.stats().pairs_evaluated, pass.stats().pairs_culled);
    EXPECT_LT(e, kTolerance);
    EXPECT_GT(ref.pairs_culled, 0u);
    EXPECT_EQ(pass.stats().pairs_culled, ref.pairs_culled);
    EXPECT_EQ(pass.stats().pairs_evaluated, ref.pairs_evaluated);
  }
}

// brf_gather.comp.glsl gathers 4 consecutive vertices of an instance per invocation; an
// instance's last invocation holds 1, 2 or 3 when its vertex count is no multiple of 4 (box
// meshes have 6 (n + 1)^2: 2 mod 4 at most). Boxes with 1 and 3 vertices added (near face
// vertices, same normal, in no triangle): 55, 57 and 54 vertices, several instances of each
// in one frame, against the twin, and every instance's last vertices on their own.
TEST(BrfGpuPass, GatherCoversVertexCountsThatAreNoMultipleOfFour) {
  auto ctx = headless_or_fail();
  struct Model {
    gi::BrfMesh mesh;
    gi::BrfBasis basis;
    gi::BasisRadianceField field;
  };
  std::vector<Model> ms;
  for (int extra : {1, 3, 0}) {
    Model m;
    m.mesh = box({0.3f, 0.25f, 0.2f}, 2);
    for (int k = 0; k < extra; ++k) {
      const std::size_t a = static_cast<std::size_t>(4 * k), b = a + 1;
      m.mesh.positions.push_back(0.9f * m.mesh.positions[a] + 0.1f * m.mesh.positions[b]);
      m.mesh.normals.push_back(m.mesh.normals[a]);
    }
    m.basis = gi::compute_pca_basis(m.mesh, {.lights = 64, .basis = 6}).value();
    m.field = gi::compute_basis_radiance_field(m.mesh, m.basis,
                                               {.spheres = 5, .face_resolution = 5, .sh_bands = 3, .directions = 64})
                  .value();
    ms.push_back(std::move(m));
  }
  ASSERT_EQ(ms[0].mesh.positions.size() % 4, 3u);
  ASSERT_EQ(ms[1].mesh.positions.size() % 4, 1u);
  ASSERT_EQ(ms[2].mesh.positions.size() % 4, 2u);
  std::vector<gi::BrfModel> gpu_models;
  for (const Model& m : ms) gpu_models.push_back({"", m.mesh, m.basis, m.field});
  auto created = gi::BrfGpuPass::create(gpu_models);
  ASSERT_TRUE(static_cast<bool>(created)) << created.error().to_string();
  gi::BrfGpuPass& pass = *created;
  const std::vector<gi::BrfInstance> instances = {{0, pose({-0.5f, 0.0f, 0.0f}, 0.4f, {0, 1, 0}), {0.8f, 0.2f, 0.1f}},
                                                  {1, pose({0.4f, 0.1f, 0.05f}, 0.3f, {1, 1, 0}), {0.7f, 0.7f, 0.7f}},
                                                  {2, pose({0.0f, 0.1f, 0.6f}, -0.6f, {0, 1, 1}), {0.2f, 0.5f, 0.8f}},
                                                  {1, pose({0.0f, -0.6f, 0.0f}, 0.2f, {1, 0, 0}), {0.6f, 0.6f, 0.3f}},
                                                  {0, pose({-0.1f, 0.6f, -0.4f}, 1.0f, {0, 0, 1}), {0.5f, 0.8f, 0.5f}}};
  std::vector<gi::BrfObject> objects;
  std::vector<std::vector<glm::vec3>> incoming;
  const glm::vec3 light(-1.0f, 1.5f, 0.8f);
  for (const gi::BrfInstance& i : instances) {
    const Model& m = ms[i.model];
    objects.push_back({&m.mesh, &m.basis, &m.field, i.object_to_world, i.albedo});
    const gi::BrfWorldVertices v = gi::brf_world_vertices(objects.back());
    auto& e = incoming.emplace_back();
    for (std::size_t j = 0; j < v.positions.size(); ++j) {
      const glm::vec3 d = light - v.positions[j];
      e.push_back(glm::vec3(4.0f * std::max(0.0f, glm::dot(v.normals[j], glm::normalize(d))) / glm::dot(d, d)) +
                  glm::vec3(0.05f));
    }
  }
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f};
  const auto status = pass.run(instances, incoming, settings);
  ASSERT_TRUE(status.ok()) << status.error().to_string();
  const gi::BrfResult ref = gi::brf_interreflect(objects, incoming, settings);
  const double e = vertices_error(pass, ref);
  std::printf("vertex counts 55 / 57 / 54: rel RMSE %.2e\n", e);
  EXPECT_LT(e, kTolerance);
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const auto v = pass.read_back_vertices(i);
    ASSERT_EQ(v.size(), ref.indirect[i].size());
    const std::span<const glm::vec3> tail_gpu(v.end() - 4, v.end()),
        tail_cpu(ref.indirect[i].end() - 4, ref.indirect[i].end());
    EXPECT_LT(relative_rmse(tail_gpu, tail_cpu), kTolerance) << "instance " << i << "'s last 4 vertices";
  }
}

TEST(BrfGpuPass, MovingOneObjectRecomputesOnlyItsPairs) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  const StaticPoints floor = static_points();
  ASSERT_TRUE(pass.set_static_receivers(floor.positions, floor.normals).ok());
  auto instances = three_objects();
  // The relative-pose cache alone: with occlusion the moved object stands between the other
  // two and their pair is evaluated again too (BrfOcclusion.GpuPassMatchesItsTwin...).
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f, .occlusion = false};
  ASSERT_TRUE(pass.run(instances, incoming_light(instances, {-1.0f, 1.5f, 0.8f}), settings).ok());

  instances[1].object_to_world = pose({0.5f, 0.15f, 0.1f}, 0.5f, {1, 1, 0}, 1.1f);
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  // Pairs with instance 1 as source or receiver: 2 x (n - 1) = 4 of 6.
  EXPECT_EQ(pass.stats().pairs_evaluated, 6u);
  EXPECT_EQ(pass.stats().pairs_reused, 2u);
  EXPECT_EQ(pass.stats().static_sources_reused, 2u);
  const gi::BrfResult ref = cpu(instances, incoming, settings, &floor);
  const double e = vertices_error(pass, ref);
  const double es = relative_rmse(pass.read_back_static(), ref.static_irradiance);
  std::printf("one moved: rel RMSE %.2e, static %.2e\n", e, es);
  EXPECT_LT(e, kTolerance);
  EXPECT_LT(es, kTolerance);

  // Everything moved together: relative poses hold (pairs reused), every source moved (static re-evaluated).
  const glm::mat4 shift = glm::translate(glm::mat4(1.0f), {0.3f, 0.0f, -0.2f});
  for (auto& i : instances) i.object_to_world = shift * i.object_to_world;
  const auto incoming2 = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming2, settings).ok());
  EXPECT_EQ(pass.stats().pairs_reused, 6u);
  EXPECT_EQ(pass.stats().static_sources_reused, 0u);
  const gi::BrfResult ref2 = cpu(instances, incoming2, settings, &floor);
  EXPECT_LT(vertices_error(pass, ref2), kTolerance);
  EXPECT_LT(relative_rmse(pass.read_back_static(), ref2.static_irradiance), kTolerance);
}

TEST(BrfGpuPass, StillFrameReusesEveryPairUnderNewLight) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  const StaticPoints floor = static_points();
  ASSERT_TRUE(pass.set_static_receivers(floor.positions, floor.normals).ok());
  const auto instances = three_objects();
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 1e-3f};
  ASSERT_TRUE(pass.run(instances, incoming_light(instances, {-1.0f, 1.5f, 0.8f}), settings).ok());
  const auto incoming = incoming_light(instances, {1.2f, 1.0f, -0.5f}, 7.0f);  // the light moved, the objects did not
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_EQ(pass.stats().pairs_reused, pass.stats().pairs_evaluated);
  EXPECT_EQ(pass.stats().static_sources_reused, 3u);
  const gi::BrfResult ref = cpu(instances, incoming, settings, &floor);
  EXPECT_LT(vertices_error(pass, ref), kTolerance);
  EXPECT_LT(relative_rmse(pass.read_back_static(), ref.static_irradiance), kTolerance);
}

TEST(BrfGpuPass, InstanceCountChangeResetsTheCache) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  auto instances = three_objects();
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f};
  ASSERT_TRUE(pass.run(instances, incoming_light(instances, {-1.0f, 1.5f, 0.8f}), settings).ok());
  instances.pop_back();
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_EQ(pass.stats().pairs_evaluated, 2u);
  EXPECT_EQ(pass.stats().pairs_reused, 0u);
  EXPECT_LT(vertices_error(pass, cpu(instances, incoming, settings)), kTolerance);
  // Same count, another model in a slot: the layout changes too.
  instances[0].model = 1;
  const auto incoming2 = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming2, settings).ok());
  EXPECT_EQ(pass.stats().pairs_reused, 0u);
  EXPECT_LT(vertices_error(pass, cpu(instances, incoming2, settings)), kTolerance);
}

TEST(BrfGpuPass, FieldsSplitOverBuffersStillMatch) {
  auto ctx = headless_or_fail();
  // Each field in its own buffer: one Phi dispatch per buffer.
  // (On the GPU each channel's coefficients are padded to vec4s: the cube's 3 bands, 9 -> 12.)
  const std::size_t limit = std::max(models().cube_field.bytes() / 9 * 12, models().slab_field.bytes()) + 1024;
  gi::BrfGpuPass pass = make_pass({.max_buffer_bytes = limit});
  const auto instances = three_objects();
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  const gi::BrfUpdateSettings settings{.bounces = 3, .cull_threshold = 0.0f};
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_LT(vertices_error(pass, cpu(instances, incoming, settings)), kTolerance);
}

TEST(BrfGpuPass, OverlapsAndPointsInsideTheInnermostSphereStayFinite) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  // Two objects sharing a centre (every vertex inside the other's innermost sphere), a third
  // overlapping them; static receivers at a field centre and inside the innermost sphere.
  const std::vector<gi::BrfInstance> instances = {{0, pose({0.0f, 0.0f, 0.0f}, 0.0f, {0, 1, 0}), glm::vec3(0.8f)},
                                                  {1, pose({0.0f, 0.0f, 0.0f}, 0.7f, {0, 1, 0}), glm::vec3(0.6f)},
                                                  {0, pose({0.2f, 0.1f, 0.0f}, 0.3f, {1, 0, 0}), glm::vec3(0.5f)}};
  const StaticPoints points{{glm::vec3(0.0f), glm::vec3(0.05f, 0.02f, 0.0f), glm::vec3(0.2f, 0.1f, 0.0f)},
                            {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1)}};
  ASSERT_TRUE(pass.set_static_receivers(points.positions, points.normals).ok());
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  const gi::BrfUpdateSettings settings{.bounces = 3, .cull_threshold = 0.0f};
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  const gi::BrfResult ref = cpu(instances, incoming, settings, &points);
  for (std::size_t i = 0; i < instances.size(); ++i) EXPECT_TRUE(all_finite(pass.read_back_vertices(i))) << i;
  const auto st = pass.read_back_static();
  EXPECT_TRUE(all_finite(st));
  EXPECT_LT(vertices_error(pass, ref), kTolerance);
  EXPECT_LT(relative_rmse(st, ref.static_irradiance), kTolerance);
}

// The face seam on the GPU (brf_common.glsl's brf_seam_cell, the twin of radiance_field.cpp's):
// static receivers on a circle around the lit cube at 2.5 bounding radii, through the +x / +z
// seam of its field (45 deg, the cube unturned), facing it. The GPU equals the CPU twin and its
// light changes smoothly through the seam (largest 0.25 deg step change below 1%; 20% before
// the lookup blended across faces).
TEST(BrfGpuPass, TheLightChangesSmoothlyAcrossFaceSeamsAsOnTheCpu) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  const std::vector<gi::BrfInstance> instances = {{0, pose({0.0f, 0.0f, 0.0f}, 0.0f, {0, 1, 0}), glm::vec3(0.8f)}};
  const float r = 2.5f * models().cube_basis.radius;
  StaticPoints points;
  for (int k = 0; k <= 80; ++k) {
    const float a = glm::radians(35.0f + 0.25f * static_cast<float>(k));
    const glm::vec3 p = r * glm::vec3(std::cos(a), 0.1f, std::sin(a));
    points.positions.push_back(p);
    points.normals.push_back(glm::normalize(-p));
  }
  ASSERT_TRUE(pass.set_static_receivers(points.positions, points.normals).ok());
  const auto incoming = incoming_light(instances, {0.9f, 1.1f, 0.5f});
  const gi::BrfUpdateSettings settings{.bounces = 1, .cull_threshold = 0.0f};
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  const gi::BrfResult ref = cpu(instances, incoming, settings, &points);
  const auto gpu = pass.read_back_static();
  EXPECT_LT(relative_rmse(gpu, ref.static_irradiance), kTolerance);
  double largest = 0.0;
  for (std::size_t k = 1; k < gpu.size(); ++k) {
    ASSERT_GT(gpu[k - 1].x, 0.0f) << k;
    largest = std::max(largest, double{std::abs(gpu[k].x - gpu[k - 1].x) / gpu[k - 1].x});
  }
  std::printf("GPU, receivers through the +x / +z seam: largest 0.25 deg step change %.4f\n", largest);
  EXPECT_LT(largest, 0.01);
}

TEST(BrfGpuPass, BadInputReturnsErrors) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  const auto instances = three_objects();
  const auto incoming = incoming_light(instances, {-1.0f, 1.5f, 0.8f});
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f};

  auto bad_model = instances;
  bad_model[2].model = 7;
  auto s = pass.run(bad_model, incoming, settings);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("model 7"), std::string::npos) << s.error().to_string();

  EXPECT_FALSE(pass.run(instances, std::span(incoming).first(2), settings).ok());
  auto short_incoming = incoming;
  short_incoming[1].pop_back();
  s = pass.run(instances, short_incoming, settings);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("instance 1"), std::string::npos) << s.error().to_string();

  auto nan_pose = instances;
  nan_pose[0].object_to_world[3][1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(pass.run(nan_pose, incoming, settings).ok());
  auto singular = instances;
  singular[0].object_to_world = glm::mat4(0.0f);
  EXPECT_FALSE(pass.run(singular, incoming, settings).ok());
  auto nan_light = incoming;
  nan_light[2][5].y = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(pass.run(instances, nan_light, settings).ok());

  const glm::vec3 p[2] = {glm::vec3(0.0f), glm::vec3(1.0f)};
  const glm::vec3 nrm[1] = {glm::vec3(0, 1, 0)};
  EXPECT_FALSE(pass.set_static_receivers(p, nrm).ok());

  gi::BrfModel broken = models().gpu()[0];
  broken.basis.psi.pop_back();
  EXPECT_FALSE(gi::BrfGpuPass::create(std::span(&broken, 1)).ok());
  gi::BrfModel mismatched{"", models().cube, models().cube_basis, models().slab_field};  // 8 vs 6 functions
  EXPECT_FALSE(gi::BrfGpuPass::create(std::span(&mismatched, 1)).ok());

  // Still usable after the errors.
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_LT(vertices_error(pass, cpu(instances, incoming, settings)), kTolerance);
}

}  // namespace

// Four objects in a row 3 m apart: each source's influence (its outermost field sphere,
// ~4.2 m for the cube, ~4.1 m for the slab) reaches its neighbours only, so 6 of the 12
// pairs are candidates; the GPU pass skips the others exactly as its twin does, and with the
// limit off every pair is evaluated again.
TEST(BrfGpuPass, PairsOutsideTheInfluenceAreSkippedAsByTheTwin) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  std::vector<gi::BrfInstance> instances;
  for (int i = 0; i < 4; ++i)
    instances.push_back({static_cast<std::uint32_t>(i % 2),
                         pose({3.0f * static_cast<float>(i), 0.0f, 0.1f * static_cast<float>(i)},
                              0.3f * static_cast<float>(i), {0, 1, 0}),
                         {0.8f, 0.6f, 0.4f}});
  const auto incoming = incoming_light(instances, {4.5f, 2.0f, 0.5f}, 20.0f);
  for (float cull : {0.0f, 1e-3f}) {
    const gi::BrfUpdateSettings limited{.bounces = 2, .cull_threshold = cull};
    ASSERT_TRUE(pass.run(instances, incoming, limited).ok());
    EXPECT_EQ(pass.stats().pairs_evaluated, 6u) << "cull " << cull;
    EXPECT_EQ(pass.stats().pairs_culled, 6u) << "cull " << cull;
    EXPECT_LT(vertices_error(pass, cpu(instances, incoming, limited)), kTolerance) << "cull " << cull;
  }
  const gi::BrfUpdateSettings unlimited{.bounces = 2, .cull_threshold = 0.0f, .influence_scale = 0.0f};
  ASSERT_TRUE(pass.run(instances, incoming, unlimited).ok());
  EXPECT_EQ(pass.stats().pairs_evaluated, 12u);
  EXPECT_LT(vertices_error(pass, cpu(instances, incoming, unlimited)), kTolerance);
}

// The Phi slots follow the pairs in reach (brf_pair_influence), not n^2: the row of four
// holds 6 slots; moving the last object away drops its 2 and keeps the others' Phi (reused,
// copied into the packed layout), coming back brings them again, and every frame matches the
// twin.
TEST(BrfGpuPass, PhiSlotsFollowThePairsInReach) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  std::vector<gi::BrfInstance> instances;
  for (int i = 0; i < 4; ++i)
    instances.push_back({static_cast<std::uint32_t>(i % 2),
                         pose({3.0f * static_cast<float>(i), 0.0f, 0.1f * static_cast<float>(i)},
                              0.3f * static_cast<float>(i), {0, 1, 0}),
                         {0.8f, 0.6f, 0.4f}});
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f};
  auto check = [&](std::size_t slots, std::size_t reused) {
    const auto incoming = incoming_light(instances, {4.5f, 2.0f, 0.5f}, 20.0f);
    ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
    EXPECT_EQ(pass.stats().pair_slots, slots);
    EXPECT_EQ(pass.stats().pairs_evaluated, slots);
    EXPECT_EQ(pass.stats().pairs_reused, reused);
    EXPECT_LT(vertices_error(pass, cpu(instances, incoming, settings)), kTolerance);
  };
  check(6, 0);
  const glm::mat4 home = instances[3].object_to_world;
  instances[3].object_to_world = pose({40.0f, 0.0f, 0.0f}, 0.0f, {0, 1, 0});
  check(4, 4);  // 0-1, 1-0, 1-2, 2-1 kept
  instances[3].object_to_world = home;
  check(6, 4);  // 2-3 and 3-2 evaluated again
  check(6, 6);
}

// 240 cubes 3 m apart on a grid: each reaches its 8 neighbours at most, so the slots of the
// pairs in reach fit a buffer limit that all n (n - 1) ordered pairs' Phi would exceed 20
// times over (the cube's pair: its vertices x 8 functions as floats).
TEST(BrfGpuPass, ManyInstancesFitBecauseOnlyPairsInReachHoldPhi) {
  auto ctx = headless_or_fail();
  const std::size_t n = 240;
  const std::size_t pair_bytes = models().cube.positions.size() * 8 * sizeof(float);
  const std::size_t limit = pair_bytes * n * (n - 1) / 20;
  gi::BrfGpuPass pass = make_pass({.max_buffer_bytes = limit});
  std::vector<gi::BrfInstance> instances;
  for (std::size_t i = 0; i < n; ++i)
    instances.push_back({0,
                         pose({3.0f * static_cast<float>(i % 16), 0.0f, 3.0f * static_cast<float>(i / 16)},
                              0.1f * static_cast<float>(i), {0, 1, 0}),
                         {0.8f, 0.6f, 0.4f}});
  const auto incoming = incoming_light(instances, {20.0f, 3.0f, 20.0f}, 400.0f);
  const gi::BrfUpdateSettings settings{.bounces = 1, .cull_threshold = 0.0f, .occlusion = false};
  const auto status = pass.run(instances, incoming, settings);
  ASSERT_TRUE(status.ok()) << status.error().to_string();
  EXPECT_GT(pass.stats().pair_slots, n);
  EXPECT_LE(pass.stats().pair_slots, 8 * n);
  EXPECT_LT(pass.stats().pair_slots * pair_bytes, limit);
  // With the influence limit off every ordered pair needs a slot: above the limit, an error
  // that leaves the last frame's results in place.
  const auto before = pass.read_back_vertices(17);
  EXPECT_FALSE(pass.run(instances, incoming, {.bounces = 1, .cull_threshold = 0.0f, .influence_scale = 0.0f}).ok());
  EXPECT_EQ(pass.read_back_vertices(17), before);
  EXPECT_TRUE(all_finite(before));
}
