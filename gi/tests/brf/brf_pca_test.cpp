// The PCA basis of basis radiance fields (Iwasaki et al. §4.2, §5.2): how well N basis
// functions reproduce a rigid object's reflected light under point lights, and that a
// rank-deficient object keeps finite, bounded weights.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "brf/pca_basis.h"
#include "raytrace/embree_ray_caster.h"

namespace {

// A UV sphere of radius r with `rings` x `segments` quads.
gi::BrfMesh sphere(float r, int rings, int segments) {
  gi::BrfMesh m;
  for (int i = 0; i <= rings; ++i) {
    const float theta = std::numbers::pi_v<float> * static_cast<float>(i) / static_cast<float>(rings);
    for (int j = 0; j <= segments; ++j) {
      const float phi = 2.0f * std::numbers::pi_v<float> * static_cast<float>(j) / static_cast<float>(segments);
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(r * n);
      m.normals.push_back(n);
    }
  }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j)
      m.indices.insert(m.indices.end(),
                       {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

// A flat square of side s in the xz-plane facing +y, n x n quads.
gi::BrfMesh plate(float s, int n) {
  gi::BrfMesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      m.positions.emplace_back(s * (static_cast<float>(i) / static_cast<float>(n) - 0.5f), 0.0f,
                               s * (static_cast<float>(j) / static_cast<float>(n) - 0.5f));
      m.normals.emplace_back(0.0f, 1.0f, 0.0f);
    }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      m.indices.insert(m.indices.end(),
                       {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i + 1, j)});
  return m;
}

// Relative RMS error of the basis fit of the response to a light at `light`.
double fit_error(const gi::BrfMesh& mesh, const gi::BrfBasis& basis, glm::vec3 light) {
  gi::RtSceneData data;
  data.geometries.push_back({mesh.positions, mesh.indices});
  data.instances.push_back({0, glm::mat4(1.0f), false, 0});
  const auto caster = gi::make_embree_ray_caster(data).value();
  const std::vector<float> truth = gi::point_light_response(mesh, *caster, light);
  const std::vector<float> w = basis.fit(truth);
  for (float v : w) EXPECT_TRUE(std::isfinite(v));
  const std::vector<float> approx = basis.reconstruct(w);
  double err = 0.0, norm = 0.0;
  for (std::size_t j = 0; j < truth.size(); ++j) {
    err += std::pow(static_cast<double>(approx[j] - truth[j]), 2.0);
    norm += std::pow(static_cast<double>(truth[j]), 2.0);
  }
  return std::sqrt(err / norm);
}

TEST(BrfPcaBasis, MoreBasisFunctionsFitUnseenLightsBetter) {
  const gi::BrfMesh mesh = sphere(0.5f, 16, 32);
  // Lights not in the training set (which sits on a Fibonacci spiral at 1.5 R), at 1.5 R and 3 R.
  const glm::vec3 tests[] = {{0.61f, 0.2f, -0.43f}, {-0.3f, -0.5f, 0.52f}, {1.2f, 0.9f, 0.4f}};
  double previous = 1e9;
  for (int n : {4, 16, 32}) {
    const gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = n}).value();
    ASSERT_EQ(basis.basis_count, n);
    double worst = 0.0;
    for (glm::vec3 l : tests) worst = std::max(worst, fit_error(mesh, basis, l));
    std::printf("sphere, N = %2d: worst relative RMS error of unseen lights %.4f (condition of A %.3g)\n", n, worst,
                basis.condition);
    EXPECT_LT(worst, previous);
    previous = worst;
  }
  // A point light 1.5 radii from a sphere lights a cap of about 48 degrees with a sharp
  // terminator: its rotations need many components (measured 0.93, 0.67, 0.36 for
  // N = 4, 16, 32); the paper's N = 16 suits broader, smoother light.
  EXPECT_LT(previous, 0.45);
}

TEST(BrfPcaBasis, FlatObjectIsRankDeficientButStaysFinite) {
  // A single quad has 4 vertices: the training matrix has rank <= 4, so at most 4 basis
  // functions can be independent; the rest are dropped and A stays invertible.
  const gi::BrfMesh mesh = plate(1.0f, 1);
  const gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = 64}).value();
  std::printf("flat plate: kept %d of 64 basis functions, condition of A %.3g\n", basis.basis_count, basis.condition);
  EXPECT_LT(basis.basis_count, 64);
  EXPECT_TRUE(std::isfinite(basis.condition));
  for (float v : basis.a_inverse) ASSERT_TRUE(std::isfinite(v));
  EXPECT_LE(basis.basis_count, 4);
  EXPECT_LE(basis.condition, 1e5) << "the pseudo-inverse bounds the conditioning";
  EXPECT_LT(fit_error(mesh, basis, {0.2f, 0.4f, -0.1f}), 0.02);
  // A light below the plate gives zero everywhere: the fit is exactly zero, not noise.
  const std::vector<float> zero(mesh.positions.size(), 0.0f);
  for (float w : basis.fit(zero)) EXPECT_EQ(w, 0.0f);
}

TEST(BrfPcaBasis, BadInputIsAnErrorNotACrash) {
  gi::BrfMesh bad = sphere(1.0f, 4, 8);
  bad.positions[3].x = std::nanf("");
  EXPECT_FALSE(gi::compute_pca_basis(bad, {}).ok());
  gi::BrfMesh empty;
  EXPECT_FALSE(gi::compute_pca_basis(empty, {}).ok());
  gi::BrfMesh out_of_range = sphere(1.0f, 4, 8);
  out_of_range.indices[5] = 100000;
  EXPECT_FALSE(gi::compute_pca_basis(out_of_range, {}).ok());
  EXPECT_FALSE(gi::compute_pca_basis(sphere(1.0f, 4, 8), {.lights = 1}).ok());
}

TEST(BrfPcaBasis, ScaleInvariant) {
  // 1 cm, 1 m and 100 m spheres: the same basis up to the light's 1/d^2, so the same fit
  // error, everything finite.
  std::vector<double> errors;
  for (float r : {0.01f, 1.0f, 100.0f}) {
    const gi::BrfMesh mesh = sphere(r, 12, 24);
    const gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 128, .basis = 16}).value();
    const double e = fit_error(mesh, basis, glm::vec3(0.9f, 0.7f, -0.6f) * r);
    std::printf("sphere of radius %g m: N %d, unseen-light error %.4f\n", double{r}, basis.basis_count, e);
    EXPECT_TRUE(std::isfinite(e));
    errors.push_back(e);
  }
  EXPECT_NEAR(errors[0], errors[1], 1e-3);
  EXPECT_NEAR(errors[2], errors[1], 1e-3);
}

}  // namespace
