// Golden images: frame N of a committed session, replayed headlessly and rendered at a
// small size (tests/golden/goldens.txt lists session, frame and size), must match
// tests/golden/<session>_fNNNN.png. Lines ending in "gi" are rendered with the demo level's
// preview bake through gi::GISystem (light atlas, PRM, basis radiance fields; ctest bakes it
// first, DemoBundle.BakePreview) and compared with <session>_fNNNN_gi.png, so the replay
// suite catches regressions of the indirect light too.
//
// Metric: a pixel "differs" when any RGB channel differs by more than 8/255. The test passes
// when fewer than 0.5% of the pixels differ AND the mean absolute channel difference over
// the image is below 1/255. llvmpipe is deterministic for a given build, so on this machine
// the images are normally identical; the tolerances absorb harmless differences from other
// Mesa/LLVM/compiler versions (rounding in rasterization and shading at a few edge pixels)
// while a moved crate, a missing shadow, a switched light or a camera off by a few
// centimetres changes far more than 0.5% of the pixels or shifts the mean.
//
// On failure the actual and diff images go to GI_BINARY_DIR/golden_failures/ and the
// message gives the approval command (tools/approve-goldens.sh).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include <engine/gpu/context.h>
#include <engine/image.h>
#include <engine/renderer.h>
#include <gi/gi_system.h>

#include <game_demo/replay.h>

namespace {

struct GoldenSpec {
  std::string session;
  std::uint64_t frame = 0;
  int width = 0, height = 0;
  bool gi = false;  ///< Lit by the demo level's preview bake (gi::GISystem), not the stand-in.

  std::string name() const {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%s_f%04llu%s", session.c_str(), static_cast<unsigned long long>(frame),
                  gi ? "_gi" : "");
    return buf;
  }
};

// What DemoBundle.BakePreview (tests/CMakeLists.txt) writes: gi-bake --preset preview.
std::filesystem::path demo_bundle() {
  return std::filesystem::path(GI_BINARY_DIR) / "test-bundles" / "demo_level.gibake";
}

std::vector<GoldenSpec> golden_specs() {
  std::ifstream in(std::filesystem::path(GI_SOURCE_DIR) / "tests" / "golden" / "goldens.txt");
  std::vector<GoldenSpec> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    GoldenSpec g;
    if (!(ls >> g.session >> g.frame >> g.width >> g.height)) continue;
    std::string lighting;
    g.gi = (ls >> lighting) && lighting == "gi";
    out.push_back(g);
  }
  return out;
}

struct ImageDiff {
  double fraction_differing = 0.0;  ///< Pixels with a channel off by more than 8/255.
  double mean_abs = 0.0;            ///< Mean |difference| over all RGB channels, in 1/255 units.
  engine::ImageRgba8 diff;          ///< Per-pixel max channel difference, amplified x8, red.
};

ImageDiff compare(const engine::ImageRgba8& a, const engine::ImageRgba8& b) {
  ImageDiff d;
  d.diff.width = a.width;
  d.diff.height = a.height;
  d.diff.pixels.assign(a.pixels.size(), 0);
  std::size_t differing = 0;
  double sum = 0.0;
  const std::size_t n = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  for (std::size_t p = 0; p < n; ++p) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      const int delta = std::abs(int{a.pixels[4 * p + static_cast<std::size_t>(c)]} -
                                 int{b.pixels[4 * p + static_cast<std::size_t>(c)]});
      worst = std::max(worst, delta);
      sum += delta;
    }
    if (worst > 8) ++differing;
    d.diff.pixels[4 * p] = static_cast<std::uint8_t>(std::min(255, worst * 8));
    d.diff.pixels[4 * p + 3] = 255;
  }
  d.fraction_differing = static_cast<double>(differing) / static_cast<double>(n);
  d.mean_abs = sum / (3.0 * static_cast<double>(n));
  return d;
}

engine::ImageRgba8 render_replayed_frame(const GoldenSpec& g) {
  const std::filesystem::path file =
      std::filesystem::path(GI_SOURCE_DIR) / "tests" / "sessions" / (g.session + ".girec");
  auto session = game_demo::load_session(file);
  EXPECT_TRUE(session) << session.error().to_string();
  if (!session) return {};
  EXPECT_LT(g.frame, session->frames.size());
  session->frames.resize(std::min<std::size_t>(session->frames.size(), g.frame + 1));
  auto sim = game_demo::simulation_for_session(*session, file.string());
  EXPECT_TRUE(sim) << sim.error().to_string();
  if (!sim) return {};
  auto ctx = engine::GpuContext::create_headless();
  EXPECT_TRUE(ctx) << "no headless GL 4.5 context: " << ctx.error().to_string();
  if (!ctx) return {};
  std::unique_ptr<gi::GISystem> gi;
  // Loaded on the scene as authored, before the replay, as gi_demo does (a deforming node
  // such as the corridor door is part of the bundle's geometry at its authored pose), and
  // before the renderer: the static meshes get the atlas UVs.
  if (g.gi) {
    auto loaded = gi::GISystem::load(demo_bundle(), sim->scene());
    EXPECT_TRUE(loaded) << loaded.error().to_string() << " (ctest bakes it in DemoBundle.BakePreview; by hand: "
                        << "build/tools/gi-bake/gi-bake --scene assets/demo_level.gltf --preset preview --out "
                        << demo_bundle().string() << ")";
    if (!loaded) return {};
    gi = std::move(loaded).value();
  }
  const game_demo::ReplayOutcome out = game_demo::replay_inputs(*sim, *session);
  EXPECT_FALSE(out.mismatch.has_value()) << game_demo::describe(*out.mismatch);
  auto renderer = engine::Renderer::create(
      sim->scene().assets,
      engine::RenderSettings{.width = g.width, .height = g.height, .exposure = game_demo::kDemoExposure});
  EXPECT_TRUE(renderer) << renderer.error().to_string();
  if (!renderer) return {};
  (*renderer)->set_indirect_light(gi.get());
  (*renderer)->settings().split =
      sim->context().split_view ? engine::SplitView::DirectLeftFullRight : engine::SplitView::Off;
  (*renderer)->render(sim->registry(), sim->context().camera);
  engine::ImageRgba8 image = (*renderer)->read_ldr();
  // Every HDR pixel finite: a NaN shows as a black speck in the LDR image, too small for the
  // tolerances (walk_flashlight frame 300 had two, from pow() of a negative in the Fresnel term).
  const engine::ImageRgbaF hdr = (*renderer)->read_hdr();
  std::size_t non_finite = 0;
  for (float v : hdr.pixels) non_finite += std::isfinite(v) ? 0 : 1;
  EXPECT_EQ(non_finite, 0u) << g.name() << ": non-finite HDR values";
  renderer->reset();
  gi.reset();  // before the context
  return image;
}

TEST(GoldenImages, ReplayedSessionFramesMatchTheGoldens) {
  const std::vector<GoldenSpec> specs = golden_specs();
  ASSERT_GE(specs.size(), 1u) << "tests/golden/goldens.txt lists no golden image";
  for (const GoldenSpec& g : specs) {
    const std::string name = g.name();
    SCOPED_TRACE(name);
    const engine::ImageRgba8 actual = render_replayed_frame(g);
    ASSERT_EQ(actual.width, g.width);
    ASSERT_EQ(actual.height, g.height);
    const std::filesystem::path golden_path =
        std::filesystem::path(GI_SOURCE_DIR) / "tests" / "golden" / (std::string(name) + ".png");
    const std::filesystem::path failures = std::filesystem::path(GI_BINARY_DIR) / "golden_failures";
    const std::string approve = "tools/approve-goldens.sh " + std::filesystem::path(GI_BINARY_DIR).filename().string();
    auto golden = engine::load_png(golden_path);
    if (!golden) {
      std::filesystem::create_directories(failures);
      (void)engine::save_png(failures / (std::string(name) + "_actual.png"), actual);
      ADD_FAILURE() << "missing golden " << golden_path << " (" << golden.error().to_string() << "); review "
                    << (failures / (std::string(name) + "_actual.png")) << " and approve with: " << approve;
      continue;
    }
    ASSERT_EQ(golden->width, actual.width);
    ASSERT_EQ(golden->height, actual.height);
    const ImageDiff d = compare(actual, *golden);
    const bool ok = d.fraction_differing < 0.005 && d.mean_abs < 1.0;
    if (!ok) {
      std::filesystem::create_directories(failures);
      (void)engine::save_png(failures / (std::string(name) + "_actual.png"), actual);
      (void)engine::save_png(failures / (std::string(name) + "_diff.png"), d.diff);
    }
    EXPECT_TRUE(ok) << name << ": " << 100.0 * d.fraction_differing
                    << "% of pixels differ by > 8/255 (limit 0.5%), mean abs diff " << d.mean_abs
                    << "/255 (limit 1/255); actual and diff images in " << failures
                    << "; if the change is intended, approve with: " << approve;
  }
}

// The golden push_crates_wall_f0700_gi looks at the crate room's wall from the hub with the
// red crate right behind it. The golden's tolerance (8/255 per pixel) would let a faint leak
// through (without the static visibility, 527 floor pixels at the wall's base get 3-4/255
// redder and darker), so this compares the HDR frame with the one where the red crate stands
// in the crate room's far corner instead: left of the doorway (the hub's wall and floor) the
// two frames must be the same. Through the doorway the crate room may change.
TEST(GoldenImages, NoBounceThroughTheCrateRoomsWall) {
  const std::filesystem::path file =
      std::filesystem::path(GI_SOURCE_DIR) / "tests" / "sessions" / "push_crates_wall.girec";
  auto session = game_demo::load_session(file);
  ASSERT_TRUE(session) << session.error().to_string();
  session->frames.resize(std::min<std::size_t>(session->frames.size(), 701));
  auto sim = game_demo::simulation_for_session(*session, file.string());
  ASSERT_TRUE(sim) << sim.error().to_string();
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL 4.5 context: " << ctx.error().to_string();
  auto loaded = gi::GISystem::load(demo_bundle(), sim->scene());
  ASSERT_TRUE(loaded) << loaded.error().to_string() << " (ctest bakes it in DemoBundle.BakePreview)";
  const game_demo::ReplayOutcome out = game_demo::replay_inputs(*sim, *session);
  ASSERT_FALSE(out.mismatch.has_value()) << game_demo::describe(*out.mismatch);
  const int w = 320, h = 180;
  auto renderer = engine::Renderer::create(
      sim->scene().assets, engine::RenderSettings{.width = w, .height = h, .exposure = game_demo::kDemoExposure});
  ASSERT_TRUE(renderer) << renderer.error().to_string();
  (*renderer)->set_indirect_light(loaded->get());
  (*renderer)->render(sim->registry(), sim->context().camera);
  const engine::ImageRgbaF at_wall = (*renderer)->read_hdr();
  const engine::Entity red = engine::find_by_name(sim->registry(), "crate_red");
  ASSERT_FALSE(red.is_null());
  sim->registry().write<engine::Transform>(red).position = {13.6f, 0.0f, 1.6f};  // 5.4 m from the wall
  engine::update_world_transforms(sim->registry());
  (*renderer)->render(sim->registry(), sim->context().camera);
  const engine::ImageRgbaF away = (*renderer)->read_hdr();
  ASSERT_EQ(at_wall.pixels.size(), away.pixels.size());
  // Left of the doorway: the doorway's left edge is at x >= 205 of 320 in this frame.
  double worst = 0.0, sum = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 200; ++x)
      for (int c = 0; c < 3; ++c) {
        const std::size_t i =
            4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) +
            static_cast<std::size_t>(c);
        const double a = double{at_wall.pixels[i]}, b = double{away.pixels[i]};
        worst = std::max(worst, std::abs(a - b) / std::max(b, 1e-3));
        sum += b;
      }
  std::printf("hub side of the wall: worst relative change %.2e (mean value %.4f)\n", worst, sum / (3.0 * 200 * h));
  EXPECT_GT(sum, 0.0);
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
