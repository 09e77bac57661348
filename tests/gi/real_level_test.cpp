// Issue 32's acceptance on a real third-party level: the Dabrovic Sponza atrium (read from
// GI_EXTERNAL_ASSETS_DIR, never copied; skipped with a message without it), untextured (the
// bakers and the path tracer do not read textures yet), lit by a high sun into the courtyard
// and a gradient sky, baked at the preview preset, seen from the courtyard floor along the
// arcades: the renderer's frame against the path tracer's truth of the same state, per region
// (open courtyard, ground-floor arcades, upper gallery) and over the frame
// (gi/frame_truth.h). docs/real_level.md has the full table (both suns, two views, every
// preset) made by tools/check-real-level.sh with the same scene, lights, views and regions.
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/image.h>
#include <engine/sun.h>
#include <gi/bake.h>
#include <gi/frame_truth.h>
#include <gtest/gtest.h>

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

  // The renderer against the truth. PROVISIONAL THRESHOLDS, to be set by the lead: the issue's
  // targets (|bias| <= 5%, truth rel RMSE <= 0.10 over the frame, every region within 10%)
  // are for the medium preset; a preview bake of the sky with its shadows should come within
  // about these. On the code before the sky is baked (the renderer adds it unshadowed on
  // every static surface) they fail by far: frame bias +64%, courtyard +48%, arcades +136%,
  // gallery +83% (docs/real_level.md).
  constexpr double kFrameBias = 0.08;
  constexpr double kFrameTruthRelRmse = 0.15;
  constexpr double kRegionBias = 0.15;
  EXPECT_LE(std::fabs(report->overall.bias), kFrameBias) << "frame bias";
  EXPECT_LE(report->overall.truth_rel_rmse, kFrameTruthRelRmse) << "frame truth rel RMSE";
  for (const gi::RegionAccuracy& r : report->regions)
    if (r.name != "other") {
      EXPECT_LE(std::fabs(r.bias), kRegionBias) << r.name << " bias";
    }
}
