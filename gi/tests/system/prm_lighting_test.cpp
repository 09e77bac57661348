// The PRM provider on llvmpipe: it re-sums the panes only when a moving light changed, and
// the GPU atlas equals the CPU sum.
#define GL_GLEXT_PROTOTYPES 1
#include "system/prm_lighting.h"

#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/scene.h>

#include <cmath>
#include <cstdio>

#include "gl_readback.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
#include "prm/prm_runtime.h"
#include "transport/static_scene.h"

namespace {

using gltest::read_texture;

TEST(PrmLighting, UpdatesOnlyWhenAMovingLightChangesAndMatchesTheCpuSum) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/spot_chamber.gltf");
  ASSERT_TRUE(asset);
  engine::Scene scene = engine::instantiate(std::move(asset.value()));
  const engine::Entity spot = engine::find_by_name(scene.registry, "spot");
  scene.registry.write<engine::Light>(spot).moves = true;

  gi::PrmSettings ps;
  ps.texels_per_metre = 2.0f;
  ps.entry_points = 512;
  ps.clusters = 32;
  gi::Prm prm = gi::bake_prm(gi::bake_input_from(scene), ps).value();
  // The CPU twin sums the panes as the GPU pass holds them (RGB9E5 by default).
  gi::Prm cpu_copy = prm;
  cpu_copy.panes = gi::decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent).value();
  auto provider = gi::PrmLighting::from_bake(std::move(prm), nullptr, scene, {.active_clusters = 16});
  ASSERT_TRUE(provider) << provider.error().to_string();
  gi::PrmLighting& gi = **provider;

  const auto cpu_atlas = [&] {
    auto caster = gi::make_static_caster(gi::bake_input_from(scene)).value();
    return gi::sum_panes(
        cpu_copy,
        gi::relight_clusters(cpu_copy, gi::scene_lights(scene.registry, gi::BakeLights::Moving), *caster, 16));
  };
  const auto expect_matches_cpu = [&](const std::vector<glm::vec3>& gpu) {
    const std::vector<glm::vec3> cpu = cpu_atlas();
    ASSERT_EQ(gpu.size(), cpu.size());
    double worst = 0.0;
    for (std::size_t t = 0; t < cpu.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        const double d = std::abs(static_cast<double>(gpu[t][c] - cpu[t][c]));
        worst = std::max(worst, d / (std::abs(static_cast<double>(cpu[t][c])) + 1e-6));
      }
    std::printf("GPU vs CPU pane sum: max relative difference %.2e\n", worst);
    EXPECT_LT(worst, 1e-4);  // the same decoded panes: only the float summation order differs
  };

  const std::uint32_t tex = gi.frame().irradiance_atlas_texture.gl_name;
  ASSERT_NE(tex, 0u);
  EXPECT_EQ(gi.stats().updates, 1u);
  const std::vector<glm::vec3> first = read_texture(tex, cpu_copy.width, cpu_copy.height);
  expect_matches_cpu(first);
  for (int i = 0; i < 3; ++i) gi.frame();
  EXPECT_EQ(gi.stats().frames, 4u);
  EXPECT_EQ(gi.stats().updates, 1u) << "nothing moved: nothing recomputed";

  scene.registry.write<engine::WorldTransform>(spot).matrix[3] = glm::vec4(1.2f, 1.0f, -0.8f, 1.0f);
  gi.frame();
  EXPECT_EQ(gi.stats().updates, 2u);
  const std::vector<glm::vec3> moved = read_texture(tex, cpu_copy.width, cpu_copy.height);
  EXPECT_NE(moved, first) << "the bounce light follows the lamp";
  expect_matches_cpu(moved);
  std::printf("update: weights %.3f ms (CPU), pane sum %.3f ms (llvmpipe), %zu clusters, %zu GPU bytes\n",
              gi.stats().last_weights_ms, gi.stats().last_gpu_ms, gi.stats().last_active_clusters,
              gi.stats().gpu_bytes);

  scene.registry.write<engine::Light>(spot).enabled = false;
  gi.frame();
  EXPECT_EQ(gi.stats().updates, 3u) << "switching the lamp off is a change";
  for (const glm::vec3& e : read_texture(tex, cpu_copy.width, cpu_copy.height)) EXPECT_EQ(e, glm::vec3(0.0f));
}

// Panes coarser than the atlas (the presets' since issue 38): the provider's texture is at the
// atlas's size, its meshes carry the atlas's uv1, and it equals the CPU twin (the decoded
// panes summed, then upsampled) up to float summation order.
TEST(PrmLighting, CoarsePanesAreReadAtTheAtlasLikeTheCpuSum) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/spot_chamber.gltf");
  ASSERT_TRUE(asset);
  engine::Scene scene = engine::instantiate(std::move(asset.value()));
  const engine::Entity spot = engine::find_by_name(scene.registry, "spot");
  scene.registry.write<engine::Light>(spot).moves = true;

  gi::PrmSettings ps;
  ps.texels_per_metre = 4.0f;
  ps.pane_texels_per_metre = 2.0f;
  ps.entry_points = 512;
  ps.clusters = 32;
  gi::Prm prm = gi::bake_prm(gi::bake_input_from(scene), ps).value();
  ASSERT_TRUE(prm.atlas.has_value());
  gi::Prm cpu_copy = prm;
  cpu_copy.panes = gi::decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent).value();
  auto provider = gi::PrmLighting::from_bake(std::move(prm), nullptr, scene, {.active_clusters = 16});
  ASSERT_TRUE(provider) << provider.error().to_string();
  gi::PrmLighting& gi = **provider;
  EXPECT_EQ(gi.layout().width, cpu_copy.atlas_width());
  EXPECT_EQ(gi.layout().requested_texels_per_metre, 4.0f);

  const std::uint32_t tex = gi.frame().irradiance_atlas_texture.gl_name;
  ASSERT_NE(tex, 0u);
  auto caster = gi::make_static_caster(gi::bake_input_from(scene)).value();
  const std::vector<glm::vec3> cpu = gi::sum_panes(
      cpu_copy, gi::relight_clusters(cpu_copy, gi::scene_lights(scene.registry, gi::BakeLights::Moving), *caster, 16));
  const std::vector<glm::vec3> gpu = read_texture(tex, cpu_copy.atlas_width(), cpu_copy.atlas_height());
  ASSERT_EQ(gpu.size(), cpu.size());
  double worst = 0.0, lit = 0.0;
  for (std::size_t t = 0; t < cpu.size(); ++t) {
    lit += cpu[t].x > 0.0f;
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(static_cast<double>(gpu[t][c] - cpu[t][c])) /
                                  (std::abs(static_cast<double>(cpu[t][c])) + 1e-6));
  }
  std::printf("coarse panes: GPU vs CPU max relative difference %.2e over %.0f lit atlas texels, %zu GPU bytes\n",
              worst, lit, gi.stats().gpu_bytes);
  EXPECT_GT(lit, 0.0);
  EXPECT_LT(worst, 1e-4);
}

// Two moving lights: when one moves, only its entry irradiance is recomputed (the other's is
// cached), and the atlas still equals the CPU relight of both.
TEST(PrmLighting, OnlyTheLightThatMovedIsRecomputed) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/spot_chamber.gltf");
  ASSERT_TRUE(asset);
  engine::Scene scene = engine::instantiate(std::move(asset.value()));
  const engine::Entity spot = engine::find_by_name(scene.registry, "spot");
  scene.registry.write<engine::Light>(spot).moves = true;
  const engine::Entity second = scene.registry.create();
  engine::Light bulb;
  bulb.type = engine::LightType::Point;
  bulb.intensity = 2.0f;
  bulb.moves = true;
  scene.registry.emplace<engine::Light>(second, bulb);
  scene.registry.emplace<engine::Transform>(second, engine::Transform{.position = {-0.8f, 1.2f, 0.6f}});
  engine::update_world_transforms(scene.registry);

  gi::PrmSettings ps;
  ps.texels_per_metre = 2.0f;
  ps.entry_points = 512;
  ps.clusters = 32;
  gi::Prm prm = gi::bake_prm(gi::bake_input_from(scene), ps).value();
  // The CPU twin sums the panes as the GPU pass holds them (RGB9E5 by default).
  gi::Prm cpu_copy = prm;
  cpu_copy.panes = gi::decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent).value();
  auto provider = gi::PrmLighting::from_bake(std::move(prm), nullptr, scene, {.active_clusters = 0});
  ASSERT_TRUE(provider) << provider.error().to_string();
  gi::PrmLighting& gi = **provider;
  gi.frame();
  EXPECT_EQ(gi.stats().last_lights_recomputed, 2u);

  scene.registry.write<engine::Transform>(second).position = {0.5f, 1.0f, -0.4f};
  engine::update_world_transforms(scene.registry);
  const std::uint32_t tex = gi.frame().irradiance_atlas_texture.gl_name;
  EXPECT_EQ(gi.stats().updates, 2u);
  EXPECT_EQ(gi.stats().last_lights_recomputed, 1u);
  EXPECT_EQ(gi.stats().last_lights_reused, 1u);
  auto caster = gi::make_static_caster(gi::bake_input_from(scene)).value();
  const std::vector<glm::vec3> cpu = gi::sum_panes(
      cpu_copy, gi::relight_clusters(cpu_copy, gi::scene_lights(scene.registry, gi::BakeLights::Moving), *caster, 0));
  const std::vector<glm::vec3> gpu = read_texture(tex, cpu_copy.width, cpu_copy.height);
  double err = 0.0, norm = 0.0;
  for (std::size_t t = 0; t < cpu.size(); ++t) {
    const glm::dvec3 d = glm::dvec3(gpu[t] - cpu[t]);
    err += glm::dot(d, d);
    norm += glm::dot(glm::dvec3(cpu[t]), glm::dvec3(cpu[t]));
  }
  std::printf("cached + recomputed light vs CPU relight of both: relative RMSE %.2e\n", std::sqrt(err / norm));
  EXPECT_LT(std::sqrt(err / norm), 1e-4);  // the same decoded panes
}

}  // namespace
