// Divergent iteration (DESIGN.md §3, Dachsbacher et al. §2.2: the unoccluded transport U can
// create energy, so the symmetric scheme has no convergence proof): a stack of thin solid
// plates 0.3 m apart in a closed room, elements (0.7 m) coarse against the spacing, grows
// without bound under the symmetric iteration. The solver must detect it, fall back to the
// asymmetric scheme, and when that grows too (8 plates) stop it and keep the result finite
// and within the energy bound.
#include <gtest/gtest.h>

#include <cmath>

#include "antiradiance/antiradiance_region.h"
#include "antiradiance_scenes.h"

namespace {

gi::BakeInput stack(int plates, float albedo, float spacing) {
  gi::BakeInput in;
  for (int i = 0; i < plates; ++i) {
    const float x = spacing * static_cast<float>(i + 1);
    artest::add_mesh(in, "plate" + std::to_string(i), artest::solid_box({x, -1, -1}, {x + 0.02f, 1, 1}),
                     glm::vec3(albedo), i == 0);
  }
  // A closed room around them (inward), so light keeps bouncing.
  gi::BakePrimitive room;
  const float L = spacing * static_cast<float>(plates + 1) + 0.2f;
  artest::add_quad(room, {-0.2f, -1.2f, -1.2f}, {L, 0, 0}, {0, 2.4f, 0});
  artest::add_quad(room, {-0.2f, -1.2f, 1.2f}, {0, 2.4f, 0}, {L, 0, 0});
  artest::add_quad(room, {-0.2f, -1.2f, -1.2f}, {0, 2.4f, 0}, {0, 0, 2.4f});
  artest::add_quad(room, {L - 0.2f, -1.2f, -1.2f}, {0, 0, 2.4f}, {0, 2.4f, 0});
  artest::add_quad(room, {-0.2f, -1.2f, -1.2f}, {0, 0, 2.4f}, {L, 0, 0});
  artest::add_quad(room, {-0.2f, 1.2f, -1.2f}, {L, 0, 0}, {0, 0, 2.4f});
  artest::add_mesh(in, "room", room, glm::vec3(albedo), false);
  artest::add_point_light(in, {0.0f, 0.0f, 0.0f}, 10.0f);
  return in;
}

struct Result {
  gi::AntiradianceSolveReport report;
  double indirect_flux = 0.0;  // sum a E (first channel)
  double bound = 0.0;          // per channel: sum a albedo E_direct / (1 - albedo)
  bool finite = true;
};

Result solve(int plates) {
  gi::AntiradianceSettings s;
  s.bins_per_side = 8;
  s.patch_size_m = 0.7f;
  s.iterations = 30;
  auto r = gi::AntiradianceRegion::create(stack(plates, 0.5f, 0.3f), s);
  EXPECT_TRUE(r) << r.error().to_string();
  Result out;
  out.report = r->update();
  const auto e = r->irradiance();
  const auto& h = r->hierarchy();
  for (std::size_t l = 0; l < h.leaf_count(); ++l) {
    const auto& n = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    out.finite = out.finite && std::isfinite(e[l].x) && std::isfinite(e[l].y) && std::isfinite(e[l].z);
    out.indirect_flux += static_cast<double>(n.area_m2 * std::abs(e[l].x));
    out.bound += static_cast<double>(n.area_m2 * n.albedo.x * r->direct()[l].x) / (1.0 - 0.5);
  }
  return out;
}

TEST(AntiradianceDivergence, SymmetricIterationThatGrowsFallsBackToTheConvergingAsymmetricScheme) {
  const Result r = solve(3);
  EXPECT_TRUE(r.report.fell_back);
  EXPECT_EQ(r.report.scheme, gi::AntiradianceScheme::Asymmetric);
  EXPECT_FALSE(r.report.diverged);
  // The fallback converges to the tolerance (1e-3) inside the budget.
  EXPECT_TRUE(r.report.converged);
  EXPECT_FALSE(r.report.budget_exhausted);
  ASSERT_FALSE(r.report.residuals.empty());
  EXPECT_LT(r.report.residuals.back(), 1e-3);
  EXPECT_EQ(r.report.output_scale, 1.0f);
  EXPECT_TRUE(r.finite);
  EXPECT_GT(r.indirect_flux, 0.0);
  EXPECT_LE(r.indirect_flux, r.bound);
}

TEST(AntiradianceDivergence, WhenBothSchemesGrowTheResultStaysFiniteAndBoundedByTheReflectedFlux) {
  const Result r = solve(8);
  EXPECT_TRUE(r.report.fell_back);
  EXPECT_TRUE(r.report.diverged);
  EXPECT_TRUE(r.finite);
  EXPECT_GT(r.report.output_scale, 0.0f);
  EXPECT_LE(r.report.output_scale, 1.0f);
  EXPECT_LE(r.indirect_flux, r.bound * (1.0 + 1e-5));
}

}  // namespace
