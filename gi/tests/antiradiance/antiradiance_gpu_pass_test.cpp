// The antiradiance passes on the GPU (llvmpipe through EGL; fails, never skips, without a
// context) against their CPU twin: same tables, same summation order, so every entry must
// agree to float rounding. Tolerance per entry: 1e-4 x (the table's largest |value|) + 1e-7
// (fused multiply-adds and the order of the three-term local sums may differ by an ulp per
// operation; the largest chain is one link list of a few thousand terms).
#include <gtest/gtest.h>
#include <engine/gpu/context.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance_scenes.h"
#include "gl_context.h"

namespace {

using gltest::headless_or_fail;

float largest(const std::vector<glm::vec3>& v) {
  float m = 0.0f;
  for (const glm::vec3& x : v) m = std::max({m, std::abs(x.x), std::abs(x.y), std::abs(x.z)});
  return m;
}

void expect_close(const std::vector<glm::vec3>& cpu, const std::vector<glm::vec3>& gpu, const char* what) {
  ASSERT_EQ(cpu.size(), gpu.size()) << what;
  const float tol = 1e-4f * largest(cpu) + 1e-7f;
  std::size_t bad = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(cpu[i][c] - gpu[i][c]) <= tol)) {
        if (bad++ < 5)
          ADD_FAILURE() << what << " entry " << i << " channel " << c << ": cpu " << cpu[i][c] << " gpu " << gpu[i][c];
      }
  EXPECT_EQ(bad, 0u) << what;
}

gi::AntiradianceSettings settings(gi::AntiradianceScheme scheme) {
  gi::AntiradianceSettings s;
  s.patch_size_m = 0.5f;
  s.bins_per_side = 6;
  s.iterations = 4;
  s.antiradiance_steps = 2;
  s.scheme = scheme;
  return s;
}

TEST(AntiradianceGpuPass, SymmetricAndAsymmetricIterationsMatchTheCpuTwin) {
  engine::GpuContext ctx = headless_or_fail();
  for (auto scheme : {gi::AntiradianceScheme::Symmetric, gi::AntiradianceScheme::Asymmetric}) {
    const gi::AntiradianceSettings s = settings(scheme);
    const artest::DoorScene scene = artest::door_scene(45.0f);
    auto region = gi::AntiradianceRegion::create(scene.input, s);
    ASSERT_TRUE(region) << region.error().to_string();
    gi::CpuAntiradiancePasses cpu(region->hierarchy(), region->bins(), region->links());
    auto gpu = gi::AntiradianceGpuPass::create(region->hierarchy(), region->bins(), region->links());
    ASSERT_TRUE(gpu) << gpu.error().to_string();
    const gi::AntiradianceSolveReport rc = gi::run_antiradiance(cpu, region->direct(), s, region->hierarchy());
    const gi::AntiradianceSolveReport rg = gi::run_antiradiance(*gpu, region->direct(), s, region->hierarchy());
    EXPECT_EQ(rc.iterations, rg.iterations);
    EXPECT_EQ(rc.fell_back, rg.fell_back);
    ASSERT_EQ(rc.residuals.size(), rg.residuals.size());
    for (std::size_t i = 0; i < rc.residuals.size(); ++i) EXPECT_NEAR(rc.residuals[i], rg.residuals[i], 1e-4);
    expect_close(cpu.irradiance(), gpu->irradiance(), "irradiance");
    expect_close(cpu.exitant(), gpu->exitant(), "exitant intensity");
    EXPECT_GT(largest(cpu.irradiance()), 0.0f);
  }
}

// After the door moves: relink the moved group, upload the new links, solve again.
TEST(AntiradianceGpuPass, MatchesTheCpuTwinAfterTheDoorMovesAndIsRelinked) {
  engine::GpuContext ctx = headless_or_fail();
  const gi::AntiradianceSettings s = settings(gi::AntiradianceScheme::Symmetric);
  const artest::DoorScene scene = artest::door_scene(0.0f);
  auto region = gi::AntiradianceRegion::create(scene.input, s);
  ASSERT_TRUE(region);
  auto gpu = gi::AntiradianceGpuPass::create(region->hierarchy(), region->bins(), region->links());
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  ASSERT_TRUE(region->set_instance_transform(scene.door, artest::hinge_matrix(70.0f)));
  region->update(false);
  ASSERT_TRUE(gpu->set_links(region->links()));
  gi::CpuAntiradiancePasses cpu(region->hierarchy(), region->bins(), region->links());
  gi::run_antiradiance(cpu, region->direct(), s, region->hierarchy());
  gi::run_antiradiance(*gpu, region->direct(), s, region->hierarchy());
  expect_close(cpu.irradiance(), gpu->irradiance(), "irradiance");
  EXPECT_GT(gpu->gpu_bytes(), 0u);
}

// A warm start (the runtime's door move after its first solve): both twins solved at one
// pose, the door moved and relinked, both started from their own last tables; the GPU's
// new leaf normals and direct light are uploaded without clearing the tables.
TEST(AntiradianceGpuPass, WarmStartAfterTheDoorMovesMatchesTheCpuTwin) {
  engine::GpuContext ctx = headless_or_fail();
  gi::AntiradianceSettings s = settings(gi::AntiradianceScheme::Symmetric);
  s.iterations = 64;  // converged, as a warm start needs
  const artest::DoorScene scene = artest::door_scene(0.0f);
  auto region = gi::AntiradianceRegion::create(scene.input, s);
  ASSERT_TRUE(region);
  gi::CpuAntiradiancePasses cpu(region->hierarchy(), region->bins(), region->links());
  auto gpu = gi::AntiradianceGpuPass::create(region->hierarchy(), region->bins(), region->links());
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  ASSERT_TRUE(gi::run_antiradiance(cpu, region->direct(), s, region->hierarchy()).converged);
  ASSERT_TRUE(gi::run_antiradiance(*gpu, region->direct(), s, region->hierarchy()).converged);
  ASSERT_TRUE(region->set_instance_transform(scene.door, artest::hinge_matrix(40.0f)));
  region->update(false);
  ASSERT_TRUE(gpu->set_links(region->links()));
  const auto warm = gi::AntiradianceStart::Warm;
  const gi::AntiradianceSolveReport rc = gi::run_antiradiance(cpu, region->direct(), s, region->hierarchy(), warm);
  const gi::AntiradianceSolveReport rg = gi::run_antiradiance(*gpu, region->direct(), s, region->hierarchy(), warm);
  EXPECT_TRUE(rc.warm && rg.warm);
  EXPECT_EQ(rc.iterations, rg.iterations);
  expect_close(cpu.irradiance(), gpu->irradiance(), "irradiance");
  expect_close(cpu.exitant(), gpu->exitant(), "exitant intensity");
  // The warm start reached the cold solve's fixed point at the new pose (within the tolerance).
  gi::CpuAntiradiancePasses cold(region->hierarchy(), region->bins(), region->links());
  gi::run_antiradiance(cold, region->direct(), s, region->hierarchy());
  const std::vector<glm::vec3> a = cold.irradiance(), b = cpu.irradiance();
  const float scale = largest(a);
  for (std::size_t l = 0; l < a.size(); ++l) ASSERT_NEAR(a[l].x, b[l].x, 0.01f * scale) << l;
}

}  // namespace
