// Issue 32's acceptance on a real third-party level: the Dabrovic Sponza atrium (read from
// GI_EXTERNAL_ASSETS_DIR, never copied; skipped with a message without it), untextured (the
// renderer, the bakers and the path tracer all see the factors alone, gi::without_textures;
// the textured level's atlas against the textured path tracer is
// gi/tests/light_atlas/textured_real_level_test.cpp), lit by a high sun into the courtyard
// and a gradient sky, baked at the preview preset, seen from the courtyard floor along the
// arcades: the renderer's frame against the path tracer's truth of the same state, per region
// (open courtyard, ground-floor arcades, upper gallery) and over the frame
// (gi/frame_truth.h). docs/real_level.md has the full table (both suns, two views, every
// preset) made by tools/check-real-level.sh with the same scene, lights, views and regions.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/image.h>
#include <engine/sun.h>
#include <gi/bake.h>
#include <gi/frame_truth.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace fs = std::filesystem;

namespace {

// The lights, view and regions of docs/real_level.md (tools/check-real-level.sh).
// The sky: a clear day's gradient, E = 65 W/m^2 (green) on an open floor against the sun's
// 650 (engine::sky_irradiance_up); the sun at 74 degrees lights a band of the courtyard floor
// and the facades, hardly anything under the vaults (0.2% of the arcades' area).
const engine::SkyGradient kSky{.zenith = {10, 16, 30}, .horizon = {28, 30, 34}, .ground = {6, 6, 6}};
const engine::Sun kHighSun{.direction = {0.25f, -1.0f, 0.15f}, .irradiance = {700, 650, 600}};
// From the courtyard floor near its west end, looking east along the north arcade.
const gi::FrameCamera kCourtyardView{
    .name = "courtyard", .position_m = {-10, 1.7f, -2}, .target_m = {8, 4, 4.5f}, .yfov_rad = 1.0471976f};
// Boxes from the level's geometry, by storey: the ground storey (floor at y = 0.09, its
// vaults' tops at the gallery floor, y = 4.82) is the open courtyard between the facades
// (|x| <= 11.6, |z| <= 3.18) and the arcades around it; the upper gallery storey runs from
// 4.75 to 10.2 (its vaults' tops at 10.25), its inside and its facade; "other" is the top
// storey and the roofs. A pixel goes to the box holding its hit moved 5 cm towards the
// camera, so each face of a facade goes to the side it faces.
const std::vector<gi::WorldRegion> kRegions{
    {"courtyard", {-11.6f, -1.0f, -3.18f}, {11.6f, 4.75f, 3.18f}},
    {"arcades", {-16.3f, -1.0f, -7.3f}, {16.3f, 4.75f, 7.3f}},
    {"gallery", {-16.3f, 4.75f, -7.3f}, {16.3f, 10.2f, 7.3f}},
};

void print(const gi::RegionAccuracy& r) {
  std::printf(
      "  %-10s %6zu px  frame L %7.3f  truth L %7.3f  bias %+7.1f%% (+- %.1f%%)  rel RMSE %.3f  truth rel RMSE %.3f"
      "  reference noise %.3f%s%s\n",
      r.name.c_str(), r.pixels, r.frame_luminance, r.truth_luminance, 100.0 * r.bias, 100.0 * r.bias_noise, r.rel_rmse,
      r.truth_rel_rmse, r.reference_noise, r.problem.empty() ? "" : "  ", r.problem.c_str());
}

}  // namespace

TEST(RealLevel, SponzaUnderAHighSunAndAGradientSkyAtPreviewLooksAsThePathTracerSeesIt) {
  const fs::path file = fs::path(GI_EXTERNAL_ASSETS_DIR) / "dabrovic-sponza" / "sponza.gltf";
  if (!fs::exists(file)) GTEST_SKIP() << "external asset not found: " << file;
  auto loaded = engine::load_gltf(file);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  engine::SceneAsset asset = gi::without_textures(std::move(loaded).value());
  asset.environment.sky_gradient = kSky;
  engine::set_sun(asset, kHighSun);

  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "real_level";
  const fs::path bundle = out / "sponza_high_sun_preview.gibake";
  fs::remove_all(bundle);
  auto baked = gi::bake_bundle(gi::bake_input_from(asset), bundle, {.preset = "preview"});
  ASSERT_TRUE(baked) << baked.error().to_string();

  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  // 160 x 90 pixels, 128 paths each: ~1.8 M paths (seconds on 2 cores); the truth's own noise
  // is printed (reference noise, and the bias's share of it) so its numbers can be judged.
  auto bench = gi::FrameTruthBench::create(asset, bundle,
                                           {.width = 160, .height = 90, .samples_per_pixel = 128, .regions = kRegions});
  ASSERT_TRUE(bench) << bench.error().to_string();
  auto report = (*bench)->compare(kCourtyardView);
  ASSERT_TRUE(report) << report.error().to_string();

  std::printf("Dabrovic Sponza, untextured, high sun + gradient sky, preview bake (%s), view '%s', 160x90, %d spp:\n",
              (*bench)->gi_label().c_str(), report->camera.c_str(), 128);
  for (const gi::RegionAccuracy& r : report->regions) print(r);
  print(report->overall);
  std::printf("  %zu background pixels; frame %.1f ms; truth %.1f s\n", report->background_pixels,
              report->cost.frame_ms, report->truth_seconds);
  // The images behind the numbers (frame, truth, ratio), to look at where they differ.
  EXPECT_TRUE(engine::save_exr(out / "courtyard_frame.exr", report->frame));
  EXPECT_TRUE(engine::save_exr(out / "courtyard_truth.exr", report->truth));
  EXPECT_TRUE(engine::save_png(out / "courtyard_ratio.png", gi::ratio_image(*report)));

  // The instrument itself (these hold whatever the renderer does): every region is seen, no
  // pixel is lost to NaN, and the truth's noise is small against the 5% the issue asks for.
  EXPECT_EQ(report->nonfinite_pixels, 0u);
  for (const gi::RegionAccuracy& r : report->regions)
    if (r.name != "other") {
      EXPECT_GT(r.pixels, 160u * 90u / 50u) << r.name << " should fill over 2% of the view";
    }
  EXPECT_LT(report->overall.reference_noise, 0.10);
  EXPECT_LT(report->overall.bias_noise, 0.01);

  // The renderer against the truth, at the targets (|bias| <= 5%, truth rel RMSE
  // <= 0.10 over the frame, every region within 10%; they are set for the medium preset, and
  // this preview bake meets them here). Measured: frame +1.4%, 0.061; courtyard +0.9%,
  // arcades -0.2%, gallery +5.5% (the sun's shadow map on facades it grazes). Before the sky
  // was baked (the renderer added it unshadowed on every static surface): frame +64%,
  // courtyard +48%, arcades +136%, gallery +83%; with the sky baked but the sun's map at
  // 1024 texels: frame +4.5%, gallery +15.7% (docs/real_level.md).
  constexpr double kFrameBias = 0.05;
  constexpr double kFrameTruthRelRmse = 0.10;
  constexpr double kRegionBias = 0.10;
  EXPECT_LE(std::fabs(report->overall.bias), kFrameBias) << "frame bias";
  EXPECT_LE(report->overall.truth_rel_rmse, kFrameTruthRelRmse) << "frame truth rel RMSE";
  for (const gi::RegionAccuracy& r : report->regions)
    if (r.name != "other") {
      EXPECT_LE(std::fabs(r.bias), kRegionBias) << r.name << " bias";
    }
}

namespace {

// A 1 m crate (dynamic: the game may move it) on the floor of the north arcade, white as the
// level's stone: indexed, with face normals, a node of its own.
void add_crate(engine::SceneAsset& a, glm::vec3 centre) {
  engine::Primitive p;
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    const glm::vec3 n = axes[f / 2] * (f % 2 == 0 ? 1.0f : -1.0f);
    const glm::vec3 u = axes[(f / 2 + 1) % 3], v = glm::cross(n, u);
    const auto base = static_cast<std::uint32_t>(p.positions.size());
    for (int k = 0; k < 4; ++k) {
      const float su = (k == 1 || k == 2) ? 0.5f : -0.5f, sv = k >= 2 ? 0.5f : -0.5f;
      p.positions.push_back(0.5f * n + su * u + sv * v);
      p.normals.push_back(n);
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) p.indices.push_back(base + i);
  }
  engine::Material m;
  m.name = "crate";
  m.base_color = glm::vec4(0.7f, 0.7f, 0.7f, 1.0f);
  m.roughness = 1.0f;
  m.metallic = 0.0f;
  a.materials.push_back(m);
  p.material = static_cast<int>(a.materials.size()) - 1;
  a.meshes.push_back({.name = "crate", .primitives = {p}});
  engine::Node node;
  node.name = "crate";
  node.mesh = static_cast<int>(a.meshes.size()) - 1;
  node.translation = centre;
  node.gi.mobility = engine::Mobility::Dynamic;
  a.nodes.push_back(node);
}

}  // namespace

// "A dynamic object in an arcade is as dark as the wall behind it" (issue 32): a crate the
// game may move stands in the north arcade, out of the sun. It gets no atlas: its sky term is
// the renderer's, scaled by its measured sky visibility (an ambient cube at its centre), and
// its bounced light comes from the basis radiance fields' world probes (the atlas's VPLs,
// which hold the sky and the sun's bounce). Against the path tracer, the crate's pixels and
// the arcade's around it.
TEST(RealLevel, ADynamicCrateInAnArcadeIsAsDarkAsTheArcade) {
  const fs::path file = fs::path(GI_EXTERNAL_ASSETS_DIR) / "dabrovic-sponza" / "sponza.gltf";
  if (!fs::exists(file)) GTEST_SKIP() << "external asset not found: " << file;
  auto loaded = engine::load_gltf(file);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  engine::SceneAsset asset = gi::without_textures(std::move(loaded).value());
  asset.environment.sky_gradient = kSky;
  engine::set_sun(asset, kHighSun);
  const glm::vec3 crate(2.0f, 0.6f, 5.3f);
  add_crate(asset, crate);

  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "real_level";
  const fs::path bundle = out / "sponza_crate_preview.gibake";
  fs::remove_all(bundle);
  auto baked = gi::bake_bundle(gi::bake_input_from(asset), bundle, {.preset = "preview"});
  ASSERT_TRUE(baked) << baked.error().to_string();
  bool brf = false;
  for (const auto& m : baked->baked) brf = brf || m.method == "brf";
  EXPECT_TRUE(brf) << "the planner plans basis radiance fields for the crate";

  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  const std::vector<gi::WorldRegion> regions{
      {"crate", crate - glm::vec3(0.56f), crate + glm::vec3(0.56f)},
      {"arcade", {-4.0f, -1.0f, 3.2f}, {8.0f, 4.75f, 7.3f}},
  };
  auto bench = gi::FrameTruthBench::create(asset, bundle,
                                           {.width = 128, .height = 96, .samples_per_pixel = 256, .regions = regions});
  ASSERT_TRUE(bench) << bench.error().to_string();
  // From inside the arcade, west of the crate, looking along the arcade at it.
  auto report =
      (*bench)->compare({.name = "crate", .position_m = {-1.0f, 1.5f, 4.6f}, .target_m = crate, .yfov_rad = 0.8f});
  ASSERT_TRUE(report) << report.error().to_string();
  std::printf("Dabrovic Sponza, a dynamic crate in the north arcade, preview bake (%s), 128x96, 256 spp:\n",
              (*bench)->gi_label().c_str());
  for (const gi::RegionAccuracy& r : report->regions) print(r);
  print(report->overall);
  EXPECT_TRUE(engine::save_exr(out / "crate_frame.exr", report->frame));
  EXPECT_TRUE(engine::save_exr(out / "crate_truth.exr", report->truth));
  EXPECT_TRUE(engine::save_png(out / "crate_ratio.png", gi::ratio_image(*report)));
  ASSERT_GE(report->regions.size(), 2u);
  const gi::RegionAccuracy& on_crate = report->regions[0];
  const gi::RegionAccuracy& arcade = report->regions[1];
  ASSERT_GT(on_crate.pixels, 128u * 96u / 20u) << "the crate should fill over 5% of the view";
  // Measured: crate -9.8% (its bounce light from the world probes, the atlas's 300 VPLs at
  // preview over the whole level), arcade +0.3%; crate / arcade 0.91 against the truth's 1.01.
  // (The arcade around it was +136% while the renderer drew the sky unshadowed on it.)
  const double crate_vs_arcade = on_crate.frame_luminance / arcade.frame_luminance;
  const double truth_crate_vs_arcade = on_crate.truth_luminance / arcade.truth_luminance;
  std::printf("  crate / arcade: frame %.3f, truth %.3f\n", crate_vs_arcade, truth_crate_vs_arcade);
  EXPECT_NEAR(crate_vs_arcade / truth_crate_vs_arcade, 1.0, 0.15) << "the crate is as dark as the arcade";
  EXPECT_LE(std::fabs(on_crate.bias), 0.15) << "crate bias";
  EXPECT_LE(std::fabs(arcade.bias), 0.10) << "arcade bias";
}
