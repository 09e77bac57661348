// The basis-radiance-field interreflection on the GPU (llvmpipe through EGL; fails, never
// skips, without a context) against its CPU twin gi::brf_interreflect: the same pairs, the
// same bounces, the same static receivers, relative RMSE below 1e-3 (float32 on both sides;
// the GPU fits sum in float where the CPU sums in double). Phi caching: moving one object
// re-evaluates only its pairs, a still frame none. Glossy objects (a GGX lobe separated into
// terms) as sources and receivers: every term of every vertex against the twin.
#include "brf/brf_gpu_pass.h"

#include <engine/gpu/context.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <vector>

#include "brf/brdf_separation.h"
#include "brf/brf_runtime.h"
#include "brf_scenes.h"
#include "gl_context.h"

namespace {

constexpr double kTolerance = 1e-3;

using gltest::headless_or_fail;

gi::BrfMesh box(glm::vec3 half, int n) { return brftest::box(half, n); }

// Two small models: a cube (8 functions, 3 SH bands) and a slab (6 functions, 4 bands), so
// offsets, basis counts and band counts differ between pairs.
struct Models {
  gi::BrfMesh cube = box({0.3f, 0.3f, 0.3f}, 3);
  gi::BrfMesh slab = box({0.2f, 0.4f, 0.25f}, 3);
  gi::BrfBasis cube_basis = gi::compute_pca_basis(cube, {.lights = 64, .basis = 8}).value();
  gi::BrfBasis slab_basis = gi::compute_pca_basis(slab, {.lights = 64, .basis = 6}).value();
  gi::BasisRadianceField cube_field =
      gi::compute_basis_radiance_field(cube, cube_basis,
                                       {.spheres = 6, .face_resolution = 6, .sh_bands = 3, .directions = 64})
          .value();
  gi::BasisRadianceField slab_field =
      gi::compute_basis_radiance_field(slab, slab_basis,
                                       {.spheres = 5, .face_resolution = 5, .sh_bands = 4, .directions = 64})
          .value();
  std::vector<gi::BrfGpuModel> gpu() const {
    return {{&cube, &cube_basis, &cube_field}, {&slab, &slab_basis, &slab_field}};
  }
  gi::BrfObject object(const gi::BrfGpuInstance& i) const {
    return i.model == 0 ? gi::BrfObject{&cube, &cube_basis, &cube_field, i.object_to_world, i.albedo}
                        : gi::BrfObject{&slab, &slab_basis, &slab_field, i.object_to_world, i.albedo};
  }
};

const Models& models() {
  static const Models m;
  return m;
}

glm::mat4 pose(glm::vec3 t, float angle, glm::vec3 axis, float scale = 1.0f) {
  return glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), t), angle, glm::normalize(axis)), glm::vec3(scale));
}

std::vector<gi::BrfGpuInstance> three_objects(float third_distance = 0.7f) {
  return {{0, pose({-0.5f, 0.0f, 0.0f}, 0.4f, {0, 1, 0}), {0.8f, 0.2f, 0.1f}},
          {1, pose({0.45f, 0.1f, 0.05f}, 0.3f, {1, 1, 0}, 1.1f), {0.7f, 0.7f, 0.7f}},
          {0, pose({0.0f, 0.1f, third_distance}, -0.6f, {0, 1, 1}, 0.8f), {0.2f, 0.5f, 0.8f}}};
}

// Light arriving at each vertex from a point light (unshadowed) plus a constant sky term.
std::vector<std::vector<glm::vec3>> incoming_light(std::span<const gi::BrfGpuInstance> instances, glm::vec3 light,
                                                   float strength = 4.0f) {
  std::vector<std::vector<glm::vec3>> in;
  for (const gi::BrfGpuInstance& i : instances) {
    const gi::BrfWorldVertices v = gi::brf_world_vertices(models().object(i));
    auto& e = in.emplace_back();
    for (std::size_t j = 0; j < v.positions.size(); ++j) {
      const glm::vec3 d = light - v.positions[j];
      const float cos_theta = std::max(0.0f, glm::dot(v.normals[j], glm::normalize(d)));
      e.push_back(glm::vec3(1.0f, 0.8f, 0.6f) * (strength * cos_theta / glm::dot(d, d)) + glm::vec3(0.05f));
    }
  }
  return in;
}

struct StaticPoints {
  std::vector<glm::vec3> positions, normals;
};

// A floor under the objects, a wall beside them and two points far outside every field. The
// grid is offset by odd amounts: a point whose source-space direction ties two cube faces
// exactly (|x| == |y|, as the slab's rotation about (1, 1, 0) makes of (1, -0.45, -0.4)) may
// round to either face on CPU and GPU, and the field lookup jumps across face seams.
StaticPoints static_points() {
  StaticPoints s;
  for (int i = 0; i < 12; ++i)
    for (int k = 0; k < 12; ++k) {
      s.positions.emplace_back(-1.187f + 0.2f * static_cast<float>(i), -0.45f, -0.991f + 0.2f * static_cast<float>(k));
      s.normals.emplace_back(0.0f, 1.0f, 0.0f);
      s.positions.emplace_back(1.3f, -0.4f + 0.1f * static_cast<float>(i), -0.6f + 0.12f * static_cast<float>(k));
      s.normals.emplace_back(-1.0f, 0.0f, 0.0f);
    }
  s.positions.emplace_back(40.0f, 0.0f, 0.0f);
  s.normals.emplace_back(-1.0f, 0.0f, 0.0f);
  s.positions.emplace_back(0.0f, -30.0f, 0.0f);
  s.normals.emplace_back(0.0f, 1.0f, 0.0f);
  return s;
}

gi::BrfResult cpu(std::span<const gi::BrfGpuInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                  const gi::BrfUpdateSettings& settings, const StaticPoints* receivers = nullptr) {
  std::vector<gi::BrfObject> objects;
  for (const auto& i : instances) objects.push_back(models().object(i));
  gi::BrfStaticReceivers r;
  if (receivers != nullptr) r = {receivers->positions, receivers->normals};
  return gi::brf_interreflect(objects, incoming, settings, r);
}

// sqrt(sum |a - b|^2 / sum |b|^2); 0 when both are zero.
double relative_rmse(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double* norm_out = nullptr) {
  EXPECT_EQ(a.size(), b.size());
  double err = 0.0, norm = 0.0;
  for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
    const glm::dvec3 d = glm::dvec3(a[k]) - glm::dvec3(b[k]);
    err += glm::dot(d, d);
    norm += glm::dot(glm::dvec3(b[k]), glm::dvec3(b[k]));
  }
  if (norm_out != nullptr) *norm_out = norm;
  const double e = norm > 0.0 ? std::sqrt(err / norm) : std::sqrt(err);
  if (e >= kTolerance)  // name the worst entries
    for (std::size_t k = 0, shown = 0; k < std::min(a.size(), b.size()) && shown < 6; ++k)
      if (glm::length(a[k] - b[k]) > 1e-3f * glm::length(b[k]) + 1e-6f) {
        std::printf("  [%zu] gpu (%g %g %g) cpu (%g %g %g)\n", k, double(a[k].x), double(a[k].y), double(a[k].z),
                    double(b[k].x), double(b[k].y), double(b[k].z));
        ++shown;
      }
  return e;
}

double vertices_error(const gi::BrfGpuPass& pass, const gi::BrfResult& ref) {
  std::vector<glm::vec3> a, b;
  for (std::size_t i = 0; i < ref.indirect.size(); ++i) {
    const auto v = pass.read_back_vertices(i);
    a.insert(a.end(), v.begin(), v.end());
    b.insert(b.end(), ref.indirect[i].begin(), ref.indirect[i].end());
  }
  double norm = 0.0;
  const double e = relative_rmse(a, b, &norm);
  EXPECT_GT(norm, 0.0) << "the scene has no interreflection to compare";
  return e;
}

bool all_finite(std::span<const glm::vec3> v) {
  for (const glm::vec3& x : v)
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) return false;
  return true;
}

gi::BrfGpuPass make_pass(const gi::BrfGpuPassOptions& options = {}) {
  auto pass = gi::BrfGpuPass::create(models().gpu(), options);
  if (!pass) {
    ADD_FAILURE() << pass.error().to_string();
    std::abort();
  }
  return std::move(pass).value();
}

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
  std::vector<gi::BrfGpuModel> gpu_models;
  for (const Model& m : ms) gpu_models.push_back({&m.mesh, &m.basis, &m.field});
  auto created = gi::BrfGpuPass::create(gpu_models);
  ASSERT_TRUE(static_cast<bool>(created)) << created.error().to_string();
  gi::BrfGpuPass& pass = *created;
  const std::vector<gi::BrfGpuInstance> instances = {
      {0, pose({-0.5f, 0.0f, 0.0f}, 0.4f, {0, 1, 0}), {0.8f, 0.2f, 0.1f}},
      {1, pose({0.4f, 0.1f, 0.05f}, 0.3f, {1, 1, 0}), {0.7f, 0.7f, 0.7f}},
      {2, pose({0.0f, 0.1f, 0.6f}, -0.6f, {0, 1, 1}), {0.2f, 0.5f, 0.8f}},
      {1, pose({0.0f, -0.6f, 0.0f}, 0.2f, {1, 0, 0}), {0.6f, 0.6f, 0.3f}},
      {0, pose({-0.1f, 0.6f, -0.4f}, 1.0f, {0, 0, 1}), {0.5f, 0.8f, 0.5f}}};
  std::vector<gi::BrfObject> objects;
  std::vector<std::vector<glm::vec3>> incoming;
  const glm::vec3 light(-1.0f, 1.5f, 0.8f);
  for (const gi::BrfGpuInstance& i : instances) {
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
    const std::span<const glm::vec3> tail_gpu(v.end() - 4, v.end()), tail_cpu(ref.indirect[i].end() - 4, ref.indirect[i].end());
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
  const std::vector<gi::BrfGpuInstance> instances = {{0, pose({0.0f, 0.0f, 0.0f}, 0.0f, {0, 1, 0}), glm::vec3(0.8f)},
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
  const std::vector<gi::BrfGpuInstance> instances = {{0, pose({0.0f, 0.0f, 0.0f}, 0.0f, {0, 1, 0}), glm::vec3(0.8f)}};
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

  gi::BrfGpuModel broken = models().gpu()[0];
  broken.field = nullptr;
  EXPECT_FALSE(gi::BrfGpuPass::create(std::span(&broken, 1)).ok());
  gi::BrfGpuModel mismatched{&models().cube, &models().cube_basis, &models().slab_field};  // 8 vs 6 functions
  EXPECT_FALSE(gi::BrfGpuPass::create(std::span(&mismatched, 1)).ok());

  // Still usable after the errors.
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_LT(vertices_error(pass, cpu(instances, incoming, settings)), kTolerance);
}


// Glossy scenes: model 0 the diffuse cube, 1 a glossy cube (GGX f0 0.9, alpha 0.5, 4+ terms,
// 4 SH bands), 2 a glossy slab (3 bands) sharing the lobe.
struct GlossyModels {
  gi::BrdfSeparation sep = gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.5f}, {.terms = 4, .resolution = 16}).value();
  gi::BrfMesh cube = box({0.3f, 0.3f, 0.3f}, 3);
  gi::BrfMesh slab = box({0.2f, 0.4f, 0.25f}, 3);
  gi::BrfBasis cube_basis = gi::compute_pca_basis(cube, {.lights = 64, .basis = 6}, &sep).value();
  gi::BrfBasis slab_basis = gi::compute_pca_basis(slab, {.lights = 64, .basis = 5}, &sep).value();
  gi::BasisRadianceField cube_field =
      gi::compute_basis_radiance_field(cube, cube_basis,
                                       {.spheres = 5, .face_resolution = 5, .sh_bands = 4, .directions = 64}, &sep)
          .value();
  gi::BasisRadianceField slab_field =
      gi::compute_basis_radiance_field(slab, slab_basis,
                                       {.spheres = 4, .face_resolution = 5, .sh_bands = 3, .directions = 64}, &sep)
          .value();
  std::vector<gi::BrfGpuModel> gpu() const {
    const Models& d = models();
    return {{&d.cube, &d.cube_basis, &d.cube_field}, {&cube, &cube_basis, &cube_field, &sep},
            {&slab, &slab_basis, &slab_field, &sep}};
  }
  gi::BrfObject object(const gi::BrfGpuInstance& i) const {
    const Models& d = models();
    if (i.model == 0) return {&d.cube, &d.cube_basis, &d.cube_field, i.object_to_world, i.albedo};
    if (i.model == 1) return {&cube, &cube_basis, &cube_field, i.object_to_world, i.albedo, &sep, i.specular};
    return {&slab, &slab_basis, &slab_field, i.object_to_world, i.albedo, &sep, i.specular};
  }
};

const GlossyModels& glossy_models() {
  static const GlossyModels m;
  return m;
}

std::vector<gi::BrfGpuInstance> glossy_objects(float third_distance = 0.7f) {
  return {{1, pose({-0.5f, 0.0f, 0.0f}, 0.4f, {0, 1, 0}), {0.3f, 0.2f, 0.1f}, {0.9f, 0.8f, 0.6f}},
          {2, pose({0.45f, 0.1f, 0.05f}, 0.3f, {1, 1, 0}, 1.1f), {0.2f, 0.3f, 0.3f}, {0.7f, 0.9f, 1.0f}},
          {0, pose({0.0f, 0.1f, third_distance}, -0.6f, {0, 1, 1}, 0.8f), {0.2f, 0.5f, 0.8f}}};
}

// The light of incoming_light, and for glossy objects E_k = g_k(w_light) x the point light's
// irradiance (as brf_direct_light), [k x V + j].
std::vector<std::vector<glm::vec3>> glossy_incoming(std::span<const gi::BrfGpuInstance> instances, glm::vec3 light) {
  std::vector<std::vector<glm::vec3>> in;
  for (const gi::BrfGpuInstance& i : instances) {
    const gi::BrfObject object = glossy_models().object(i);
    const gi::BrfWorldVertices v = gi::brf_world_vertices(object);
    const std::size_t nv = v.positions.size();
    auto& e = in.emplace_back(nv * static_cast<std::size_t>(object.terms()), glm::vec3(0.0f));
    for (std::size_t j = 0; j < nv; ++j) {
      const glm::vec3 d = light - v.positions[j];
      const float cos_theta = std::max(0.0f, glm::dot(v.normals[j], glm::normalize(d)));
      const glm::vec3 point = glm::vec3(1.0f, 0.8f, 0.6f) * (4.0f * cos_theta / glm::dot(d, d));
      e[j] = point + glm::vec3(0.05f);
      if (object.glossy == nullptr) continue;
      const glm::vec3 w = glm::transpose(v.frames[j]) * glm::normalize(d);
      for (int k = 1; k < object.terms(); ++k)
        e[static_cast<std::size_t>(k) * nv + j] = object.glossy->g_at(k - 1, w) * point;
    }
  }
  return in;
}

gi::BrfResult glossy_cpu(std::span<const gi::BrfGpuInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                         const gi::BrfUpdateSettings& settings, const StaticPoints* receivers = nullptr) {
  std::vector<gi::BrfObject> objects;
  for (const auto& i : instances) objects.push_back(glossy_models().object(i));
  gi::BrfStaticReceivers r;
  if (receivers != nullptr) r = {receivers->positions, receivers->normals};
  return gi::brf_interreflect(objects, incoming, settings, r);
}

// Relative RMSE over every term of every instance; `glossy_only`: the terms k >= 1 only.
double terms_error(const gi::BrfGpuPass& pass, std::span<const gi::BrfGpuInstance> instances, const gi::BrfResult& ref,
                   bool glossy_only = false) {
  std::vector<glm::vec3> a, b;
  for (std::size_t i = 0; i < ref.indirect.size(); ++i) {
    const auto v = pass.read_back_terms(i);
    EXPECT_EQ(v.size(), ref.indirect[i].size()) << i;
    const std::size_t nv = glossy_models().object(instances[i]).mesh->positions.size();
    // vertex_buffer keeps the irradiance first.
    const auto e0 = pass.read_back_vertices(i);
    EXPECT_EQ(e0.size(), nv);
    for (std::size_t j = 0; j < std::min(nv, v.size()); ++j) EXPECT_EQ(e0[j], v[j]);
    const std::size_t first = glossy_only ? nv : 0;
    if (v.size() < first || ref.indirect[i].size() < first) continue;
    a.insert(a.end(), v.begin() + static_cast<std::ptrdiff_t>(first), v.end());
    b.insert(b.end(), ref.indirect[i].begin() + static_cast<std::ptrdiff_t>(first), ref.indirect[i].end());
  }
  double norm = 0.0;
  const double e = relative_rmse(a, b, &norm);
  EXPECT_GT(norm, 0.0) << "the scene has no interreflection to compare";
  return e;
}

constexpr double kGlossyTolerance = 1e-4;

gi::BrfGpuPass make_glossy_pass() {
  auto pass = gi::BrfGpuPass::create(glossy_models().gpu());
  if (!pass) {
    ADD_FAILURE() << pass.error().to_string();
    std::abort();
  }
  return std::move(pass).value();
}

TEST(BrfGpuPass, GlossyObjectsMatchTheCpuTwinInEveryTerm) {
  auto ctx = headless_or_fail();
  ASSERT_GT(glossy_models().sep.terms, 1);
  gi::BrfGpuPass pass = make_glossy_pass();
  const StaticPoints floor = static_points();
  ASSERT_TRUE(pass.set_static_receivers(floor.positions, floor.normals).ok());
  const auto instances = glossy_objects();
  const auto incoming = glossy_incoming(instances, {-1.0f, 1.5f, 0.8f});
  for (int bounces : {1, 3}) {
    const gi::BrfUpdateSettings settings{.bounces = bounces, .cull_threshold = 0.0f};
    const auto status = pass.run(instances, incoming, settings);
    ASSERT_TRUE(status.ok()) << status.error().to_string();
    const gi::BrfResult ref = glossy_cpu(instances, incoming, settings, &floor);
    const double e = terms_error(pass, instances, ref);
    const double eg = terms_error(pass, instances, ref, true);
    double static_norm = 0.0;
    const double es = relative_rmse(pass.read_back_static(), ref.static_irradiance, &static_norm);
    std::printf("glossy (%d terms), %d bounces: all terms rel RMSE %.2e, glossy terms %.2e, static %.2e\n",
                glossy_models().sep.terms, bounces, e, eg, es);
    EXPECT_LT(e, kGlossyTolerance);
    EXPECT_LT(eg, kGlossyTolerance);
    EXPECT_GT(static_norm, 0.0);
    EXPECT_LT(es, kGlossyTolerance);
    EXPECT_EQ(pass.stats().pairs_evaluated, 6u);
  }
}

TEST(BrfGpuPass, GlossyWithCullingAndPoseCache) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_glossy_pass();
  const StaticPoints floor = static_points();
  ASSERT_TRUE(pass.set_static_receivers(floor.positions, floor.normals).ok());
  // The diffuse cube far away: its pairs are culled (with the glossy sources' multi-term weights).
  auto instances = glossy_objects(3.0f);
  const gi::BrfUpdateSettings culling{.bounces = 2, .cull_threshold = 0.05f};
  auto incoming = glossy_incoming(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming, culling).ok());
  const gi::BrfResult ref = glossy_cpu(instances, incoming, culling, &floor);
  EXPECT_GT(ref.pairs_culled, 0u);
  EXPECT_EQ(pass.stats().pairs_culled, ref.pairs_culled);
  EXPECT_EQ(pass.stats().pairs_evaluated, ref.pairs_evaluated);
  const double e = terms_error(pass, instances, ref);
  std::printf("glossy, culling: rel RMSE %.2e, %zu pairs evaluated, %zu culled\n", e, pass.stats().pairs_evaluated,
              pass.stats().pairs_culled);
  EXPECT_LT(e, kGlossyTolerance);

  // Close again, no culling; then the diffuse cube moves: the glossy pair (both ways) is kept
  // (the relative-pose cache alone, as in MovingOneObjectRecomputesOnlyItsPairs).
  instances = glossy_objects();
  const gi::BrfUpdateSettings settings{.bounces = 2, .cull_threshold = 0.0f, .occlusion = false};
  ASSERT_TRUE(pass.run(instances, glossy_incoming(instances, {-1.0f, 1.5f, 0.8f}), settings).ok());
  instances[2].object_to_world = pose({0.05f, 0.15f, 0.75f}, -0.5f, {0, 1, 1}, 0.8f);
  incoming = glossy_incoming(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_EQ(pass.stats().pairs_evaluated, 6u);
  EXPECT_EQ(pass.stats().pairs_reused, 2u);
  EXPECT_EQ(pass.stats().static_sources_reused, 2u);
  const gi::BrfResult ref2 = glossy_cpu(instances, incoming, settings, &floor);
  const double e2 = terms_error(pass, instances, ref2);
  std::printf("glossy, one moved: rel RMSE %.2e\n", e2);
  EXPECT_LT(e2, kGlossyTolerance);
  EXPECT_LT(relative_rmse(pass.read_back_static(), ref2.static_irradiance), kGlossyTolerance);

  // Everything turned and moved together: relative poses hold, so every pair's Phi (the
  // glossy rows' rotated lobes too) is reused and still right.
  const glm::mat4 shift = glm::rotate(glm::translate(glm::mat4(1.0f), {0.3f, 0.0f, -0.2f}), 0.7f, glm::vec3(0, 1, 0));
  for (auto& i : instances) i.object_to_world = shift * i.object_to_world;
  incoming = glossy_incoming(instances, {-1.0f, 1.5f, 0.8f});
  ASSERT_TRUE(pass.run(instances, incoming, settings).ok());
  EXPECT_EQ(pass.stats().pairs_reused, 6u);
  const gi::BrfResult ref3 = glossy_cpu(instances, incoming, settings, &floor);
  const double e3 = terms_error(pass, instances, ref3);
  std::printf("glossy, all turned together: rel RMSE %.2e\n", e3);
  EXPECT_LT(e3, kGlossyTolerance);
  EXPECT_LT(relative_rmse(pass.read_back_static(), ref3.static_irradiance), kGlossyTolerance);
}

TEST(BrfGpuPass, GlossyModelsAndLightMustMatch) {
  auto ctx = headless_or_fail();
  const GlossyModels& g = glossy_models();
  // A glossy field without its lobe, a lobe with another number of terms, a lobe on a diffuse field.
  const gi::BrdfSeparation other = gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.5f}, {.terms = 1, .resolution = 8}).value();
  ASSERT_NE(other.terms, g.sep.terms);
  const Models& d = models();
  for (const gi::BrfGpuModel& bad : {gi::BrfGpuModel{&g.cube, &g.cube_basis, &g.cube_field},
                                     gi::BrfGpuModel{&g.cube, &g.cube_basis, &g.cube_field, &other},
                                     gi::BrfGpuModel{&d.cube, &d.cube_basis, &d.cube_field, &g.sep}}) {
    const gi::BrfGpuModel list[2] = {{&d.slab, &d.slab_basis, &d.slab_field}, bad};
    auto pass = gi::BrfGpuPass::create(list);
    ASSERT_FALSE(pass.ok());
    EXPECT_NE(pass.error().message.find("model 1"), std::string::npos) << pass.error().to_string();
  }
  // A glossy instance given irradiance only.
  gi::BrfGpuPass pass = make_glossy_pass();
  const auto instances = glossy_objects();
  auto incoming = glossy_incoming(instances, {-1.0f, 1.5f, 0.8f});
  incoming[1].resize(g.slab.positions.size());
  const auto s = pass.run(instances, incoming, {.bounces = 2});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("instance 1"), std::string::npos) << s.error().to_string();
}

}  // namespace

// Four objects in a row 3 m apart: each source's influence (its outermost field sphere,
// ~4.2 m for the cube, ~4.1 m for the slab) reaches its neighbours only, so 6 of the 12
// pairs are candidates; the GPU pass skips the others exactly as its twin does, and with the
// limit off every pair is evaluated again.
TEST(BrfGpuPass, PairsOutsideTheInfluenceAreSkippedAsByTheTwin) {
  auto ctx = headless_or_fail();
  gi::BrfGpuPass pass = make_pass();
  std::vector<gi::BrfGpuInstance> instances;
  for (int i = 0; i < 4; ++i)
    instances.push_back({static_cast<std::uint32_t>(i % 2), pose({3.0f * static_cast<float>(i), 0.0f, 0.1f * static_cast<float>(i)}, 0.3f * static_cast<float>(i), {0, 1, 0}),
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
  std::vector<gi::BrfGpuInstance> instances;
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
  std::vector<gi::BrfGpuInstance> instances;
  for (std::size_t i = 0; i < n; ++i)
    instances.push_back({0, pose({3.0f * static_cast<float>(i % 16), 0.0f, 3.0f * static_cast<float>(i / 16)}, 0.1f * static_cast<float>(i), {0, 1, 0}),
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
