// Glossy objects on the BRF GPU pass (a GGX lobe separated into terms, as sources and
// receivers): every term of every vertex against the CPU twin gi::brf_interreflect, with and
// without culling and the pose cache, and the checks that glossy models and light match.
#include <gtest/gtest.h>

#include <cstdlib>
#include <span>
#include <vector>

#include "brf/brdf_separation.h"
#include "brf_gpu_fixtures.h"
#include "gl_context.h"

namespace {

using namespace brfgpu;
using gltest::headless_or_fail;

// Glossy scenes: model 0 the diffuse cube, 1 a glossy cube (GGX f0 0.9, alpha 0.5, 4+ terms,
// 4 SH bands), 2 a glossy slab (3 bands) sharing the lobe.
struct GlossyModels {
  gi::BrdfSeparation sep =
      gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.5f}, {.terms = 4, .resolution = 16}).value();
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
  // The pass reads its models every run: they live as long as the fixture.
  std::vector<gi::BrfModel> gpu_models = {{"", models().cube, models().cube_basis, models().cube_field},
                                          {"", cube, cube_basis, cube_field, sep},
                                          {"", slab, slab_basis, slab_field, sep}};
  const std::vector<gi::BrfModel>& gpu() const { return gpu_models; }
  gi::BrfObject object(const gi::BrfInstance& i) const {
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

std::vector<gi::BrfInstance> glossy_objects(float third_distance = 0.7f) {
  return {{1, pose({-0.5f, 0.0f, 0.0f}, 0.4f, {0, 1, 0}), {0.3f, 0.2f, 0.1f}, {0.9f, 0.8f, 0.6f}},
          {2, pose({0.45f, 0.1f, 0.05f}, 0.3f, {1, 1, 0}, 1.1f), {0.2f, 0.3f, 0.3f}, {0.7f, 0.9f, 1.0f}},
          {0, pose({0.0f, 0.1f, third_distance}, -0.6f, {0, 1, 1}, 0.8f), {0.2f, 0.5f, 0.8f}}};
}

// The light of incoming_light, and for glossy objects E_k = g_k(w_light) x the point light's
// irradiance (as brf_direct_light), [k x V + j].
std::vector<std::vector<glm::vec3>> glossy_incoming(std::span<const gi::BrfInstance> instances, glm::vec3 light) {
  std::vector<std::vector<glm::vec3>> in;
  for (const gi::BrfInstance& i : instances) {
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

gi::BrfResult glossy_cpu(std::span<const gi::BrfInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                         const gi::BrfUpdateSettings& settings, const StaticPoints* receivers = nullptr) {
  std::vector<gi::BrfObject> objects;
  for (const auto& i : instances) objects.push_back(glossy_models().object(i));
  gi::BrfStaticReceivers r;
  if (receivers != nullptr) r = {receivers->positions, receivers->normals};
  return gi::brf_interreflect(objects, incoming, settings, r);
}

// Relative RMSE over every term of every instance; `glossy_only`: the terms k >= 1 only.
double terms_error(const gi::BrfGpuPass& pass, std::span<const gi::BrfInstance> instances, const gi::BrfResult& ref,
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
  const gi::BrdfSeparation other =
      gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.5f}, {.terms = 1, .resolution = 8}).value();
  ASSERT_NE(other.terms, g.sep.terms);
  const Models& d = models();
  for (const gi::BrfModel& bad : {gi::BrfModel{"", g.cube, g.cube_basis, g.cube_field},
                                  gi::BrfModel{"", g.cube, g.cube_basis, g.cube_field, other},
                                  gi::BrfModel{"", d.cube, d.cube_basis, d.cube_field, g.sep}}) {
    const gi::BrfModel list[2] = {{"", d.slab, d.slab_basis, d.slab_field}, bad};
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
