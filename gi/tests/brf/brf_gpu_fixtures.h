#pragma once
// The scenes, references and error measures the BRF GPU pass tests share
// (brf_gpu_pass_test.cpp, brf_gpu_glossy_test.cpp): two diffuse models, three posed objects,
// static receivers, the CPU twin's result and the relative RMSE against it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>

#include "brf/brf_gpu_pass.h"
#include "brf/brf_runtime.h"
#include "brf_scenes.h"

namespace brfgpu {

constexpr double kTolerance = 1e-3;

inline gi::BrfMesh box(glm::vec3 half, int n) { return brftest::box(half, n); }

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
  // The pass reads its models every run: they live as long as the fixture.
  std::vector<gi::BrfModel> gpu_models = {{"", cube, cube_basis, cube_field}, {"", slab, slab_basis, slab_field}};
  const std::vector<gi::BrfModel>& gpu() const { return gpu_models; }
  gi::BrfObject object(const gi::BrfInstance& i) const {
    return i.model == 0 ? gi::BrfObject{&cube, &cube_basis, &cube_field, i.object_to_world, i.albedo}
                        : gi::BrfObject{&slab, &slab_basis, &slab_field, i.object_to_world, i.albedo};
  }
};

inline const Models& models() {
  static const Models m;
  return m;
}

inline glm::mat4 pose(glm::vec3 t, float angle, glm::vec3 axis, float scale = 1.0f) {
  return glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), t), angle, glm::normalize(axis)), glm::vec3(scale));
}

inline std::vector<gi::BrfInstance> three_objects(float third_distance = 0.7f) {
  return {{0, pose({-0.5f, 0.0f, 0.0f}, 0.4f, {0, 1, 0}), {0.8f, 0.2f, 0.1f}},
          {1, pose({0.45f, 0.1f, 0.05f}, 0.3f, {1, 1, 0}, 1.1f), {0.7f, 0.7f, 0.7f}},
          {0, pose({0.0f, 0.1f, third_distance}, -0.6f, {0, 1, 1}, 0.8f), {0.2f, 0.5f, 0.8f}}};
}

// Light arriving at each vertex from a point light (unshadowed) plus a constant sky term.
inline std::vector<std::vector<glm::vec3>> incoming_light(std::span<const gi::BrfInstance> instances, glm::vec3 light,
                                                          float strength = 4.0f) {
  std::vector<std::vector<glm::vec3>> in;
  for (const gi::BrfInstance& i : instances) {
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
inline StaticPoints static_points() {
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

inline gi::BrfResult cpu(std::span<const gi::BrfInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                         const gi::BrfUpdateSettings& settings, const StaticPoints* receivers = nullptr) {
  std::vector<gi::BrfObject> objects;
  for (const auto& i : instances) objects.push_back(models().object(i));
  gi::BrfStaticReceivers r;
  if (receivers != nullptr) r = {receivers->positions, receivers->normals};
  return gi::brf_interreflect(objects, incoming, settings, r);
}

// sqrt(sum |a - b|^2 / sum |b|^2); 0 when both are zero.
inline double relative_rmse(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double* norm_out = nullptr) {
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

inline double vertices_error(const gi::BrfGpuPass& pass, const gi::BrfResult& ref) {
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

inline bool all_finite(std::span<const glm::vec3> v) {
  for (const glm::vec3& x : v)
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) return false;
  return true;
}

inline gi::BrfGpuPass make_pass(const gi::BrfGpuPassOptions& options = {}) {
  auto pass = gi::BrfGpuPass::create(models().gpu(), options);
  if (!pass) {
    ADD_FAILURE() << pass.error().to_string();
    std::abort();
  }
  return std::move(pass).value();
}

}  // namespace brfgpu
