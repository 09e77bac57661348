// Scenes as artists deliver them: no KHR_lights_punctual, lit by a sky (the glTF scene's
// gi.sky, or gi-bake --sky). The planner plans the light atlas for them, the bake lights it,
// the runtime and the renderer draw it. The Avocado (Khronos sample, Draco-compressed) is
// read from GI_EXTERNAL_ASSETS_DIR, never copied; the test skips with a message without it.
#include <gtest/gtest.h>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/renderer.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>
#include <gi/plan.h>

#include <cmath>
#include <filesystem>

namespace fs = std::filesystem;

namespace {

engine::SceneAsset cornell_box_without_lamp() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset) << asset.error().to_string();
  engine::SceneAsset a = std::move(asset).value();
  for (engine::Node& n : a.nodes) n.light = -1;
  a.lights.clear();
  for (engine::Material& m : a.materials) m.emissive = glm::vec3(0.0f);
  return a;
}

}  // namespace

TEST(OutdoorScene, TheSkyAloneMakesThePlannerPlanTheLightAtlas) {
  engine::SceneAsset a = cornell_box_without_lamp();
  const gi::EffectPlan dark = gi::plan(gi::bake_input_from(a), {.preset = "preview"});
  EXPECT_FALSE(dark.effect(gi::EffectMethod::LightAtlas).enabled);
  EXPECT_NE(dark.effect(gi::EffectMethod::LightAtlas).reason.find("no light"), std::string::npos);
  a.environment.sky_radiance = glm::vec3(0.5f, 0.6f, 1.0f);
  const gi::EffectPlan lit = gi::plan(gi::bake_input_from(a), {.preset = "preview"});
  const gi::PlannedEffect& atlas = lit.effect(gi::EffectMethod::LightAtlas);
  EXPECT_TRUE(atlas.enabled) << atlas.reason;
  EXPECT_NE(atlas.reason.find("the sky lights"), std::string::npos) << atlas.reason;
  EXPECT_EQ(lit.methods_to_bake(), std::vector<std::string>{"light_atlas"});
}

TEST(OutdoorScene, AvocadoUnderASkyIsBakedLoadedAndRenderedHeadless) {
  const fs::path file = fs::path(GI_EXTERNAL_ASSETS_DIR) / "Avocado" / "glTF-Draco" / "Avocado.gltf";
  if (!fs::exists(file)) GTEST_SKIP() << "external asset not found: " << file;
  auto loaded = engine::load_gltf(file);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  engine::SceneAsset a = std::move(loaded).value();
  ASSERT_TRUE(a.lights.empty());
  const gi::EffectPlan unlit = gi::plan(gi::bake_input_from(a), {.preset = "preview"});
  EXPECT_FALSE(unlit.effect(gi::EffectMethod::LightAtlas).enabled);
  a.environment.sky_radiance = glm::vec3(1.0f);  // what gi-bake --sky 1,1,1 does

  // A camera in front of it (the file has none), framing its bounds.
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const engine::Mesh& m : a.meshes)
    for (const engine::Primitive& p : m.primitives)
      for (const glm::vec3& v : p.positions) lo = glm::min(lo, v), hi = glm::max(hi, v);
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = 0.5f * glm::length(hi - lo);
  a.cameras.push_back(
      {"camera", engine::Camera{.yfov_rad = 0.8f, .znear_m = radius * 0.05f, .zfar_m = radius * 20.0f}});
  engine::Node cam;
  cam.name = "camera";
  cam.camera = 0;
  cam.translation = centre + glm::vec3(0.0f, 0.0f, 3.0f * radius);
  a.nodes.push_back(cam);

  const fs::path bundle = fs::path(GI_BINARY_DIR) / "test_output" / "outdoor_scene" / "avocado.gibake";
  fs::remove_all(bundle);
  auto baked = gi::bake_bundle(gi::bake_input_from(a), bundle, {.preset = "preview"});
  ASSERT_TRUE(baked) << baked.error().to_string();
  ASSERT_EQ(baked->baked.size(), 1u);
  EXPECT_EQ(baked->baked[0].method, "light_atlas");

  engine::Scene scene = engine::instantiate(a);
  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  auto system = gi::GISystem::load(bundle, scene);
  ASSERT_TRUE(system) << system.error().to_string();
  auto renderer = engine::Renderer::create(scene.assets, {.width = 96, .height = 96});
  ASSERT_TRUE(renderer) << renderer.error().to_string();
  EXPECT_EQ((*renderer)->settings().sky_radiance, glm::vec3(1.0f));
  (*renderer)->set_indirect_light(system->get());
  (*renderer)->render(scene.registry, engine::find_camera(scene.registry));
  const engine::ImageRgbaF lit = (*renderer)->read_hdr();

  // The same frame with the renderer's sky set to 0: the avocado (static) is lit by the atlas
  // alone, which holds the sky's direct light shadowed by the avocado itself and its bounces,
  // so only the background changes.
  (*renderer)->settings().sky_radiance = glm::vec3(0.0f);
  (*renderer)->render(scene.registry, engine::find_camera(scene.registry));
  const engine::ImageRgbaF without = (*renderer)->read_hdr();

  std::size_t finite = 0, covered = 0, same = 0;
  double sum_lit = 0.0;
  for (std::size_t i = 0; i < lit.pixels.size(); i += 4) {
    finite += std::isfinite(lit.pixels[i]) && std::isfinite(lit.pixels[i + 1]) && std::isfinite(lit.pixels[i + 2]);
    const bool on_avocado = lit.pixels[i + 1] != 1.0f;  // the background shows the sky, radiance 1
    covered += on_avocado;
    if (!on_avocado) continue;
    sum_lit += static_cast<double>(lit.pixels[i + 1]);
    same += lit.pixels[i + 1] == without.pixels[i + 1];
  }
  EXPECT_EQ(finite, lit.pixels.size() / 4);
  EXPECT_GT(covered, lit.pixels.size() / 4 / 10) << "the avocado should fill a good part of the frame";
  EXPECT_LT(covered, lit.pixels.size() / 4) << "the sky should show around it";
  EXPECT_EQ(lit.pixels[1], 1.0f) << "a corner pixel sees the sky";
  EXPECT_EQ(without.pixels[1], 0.0f) << "and black without one";
  EXPECT_GT(sum_lit / static_cast<double>(covered), 0.05) << "the baked sky lights the avocado";
  EXPECT_EQ(same, covered) << "no sky term on the static avocado: the atlas holds the sky";
  EXPECT_TRUE((*system)->stats().disabled.empty());
  system->reset();
}

// A Khronos sample that ships its own KHR_lights_punctual lights and emissive textures (a
// street lamp, no camera, no floor): planned, baked, loaded and drawn as delivered.
TEST(OutdoorScene, KhronosLampWithItsOwnLightsIsBakedLoadedAndRenderedHeadless) {
  const fs::path file = fs::path(GI_EXTERNAL_ASSETS_DIR) / "LightsPunctualLamp" / "glTF" / "LightsPunctualLamp.gltf";
  if (!fs::exists(file)) GTEST_SKIP() << "external asset not found: " << file;
  auto loaded = engine::load_gltf(file);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  engine::SceneAsset a = std::move(loaded).value();
  ASSERT_FALSE(a.lights.empty());
  const gi::EffectPlan p = gi::plan(gi::bake_input_from(a), {.preset = "preview"});
  ASSERT_TRUE(p.effect(gi::EffectMethod::LightAtlas).enabled) << p.effect(gi::EffectMethod::LightAtlas).reason;
  // Its metal parts have roughness in the directional light maps' measured range [0.10, 0.80)
  // (docs/dlm.md, "The regime"), so they get maps beside the atlas.
  EXPECT_EQ(p.methods_to_bake(), (std::vector<std::string>{"light_atlas", "dlm"}))
      << p.effect(gi::EffectMethod::DirectionalLightMaps).reason;
  a.cameras.push_back({"camera", engine::Camera{}});
  engine::Node cam;
  cam.name = "camera";
  cam.camera = 0;
  cam.translation = {0.0f, 0.8f, 4.0f};
  a.nodes.push_back(cam);

  const fs::path bundle = fs::path(GI_BINARY_DIR) / "test_output" / "outdoor_scene" / "lamp.gibake";
  fs::remove_all(bundle);
  auto baked = gi::bake_bundle(gi::bake_input_from(a), bundle, {.preset = "preview"});
  ASSERT_TRUE(baked) << baked.error().to_string();
  engine::Scene scene = engine::instantiate(a);
  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  auto system = gi::GISystem::load(bundle, scene);
  ASSERT_TRUE(system) << system.error().to_string();
  auto renderer = engine::Renderer::create(scene.assets, {.width = 96, .height = 96});
  ASSERT_TRUE(renderer) << renderer.error().to_string();
  (*renderer)->set_indirect_light(system->get());
  (*renderer)->render(scene.registry, engine::find_camera(scene.registry));
  const engine::ImageRgbaF img = (*renderer)->read_hdr();
  std::size_t finite = 0, lit = 0;
  for (std::size_t i = 0; i < img.pixels.size(); i += 4) {
    finite += std::isfinite(img.pixels[i]) && std::isfinite(img.pixels[i + 1]) && std::isfinite(img.pixels[i + 2]);
    lit += img.pixels[i] > 0.0f;
  }
  EXPECT_EQ(finite, img.pixels.size() / 4);
  EXPECT_GT(lit, 0u);
  EXPECT_EQ((*system)->label(), std::string("light atlas + DLM"));
  EXPECT_TRUE((*system)->stats().disabled.empty());
  system->reset();
}

namespace {

// The Cornell box with its lamp (a static area light and its emissive quad) under a gradient
// sky through its open front, baked at preview with or without --include-direct, drawn with
// its GI bundle from its camera (linear HDR, 96 x 96).
engine::ImageRgbaF cornell_frame_with_sky(bool include_direct) {
  auto loaded = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(loaded) << loaded.error().to_string();
  engine::SceneAsset a = std::move(loaded).value();
  a.environment.sky_gradient = {
      .zenith = {0.1f, 0.3f, 1.2f}, .horizon = {1.0f, 0.9f, 0.6f}, .ground = {0.3f, 0.2f, 0.1f}};
  const fs::path bundle = fs::path(GI_BINARY_DIR) / "test_output" / "outdoor_scene" /
                          (include_direct ? "cornell_sky_all.gibake" : "cornell_sky.gibake");
  fs::remove_all(bundle);
  auto baked = gi::bake_bundle(gi::bake_input_from(a), bundle, {.preset = "preview", .include_direct = include_direct});
  EXPECT_TRUE(baked) << baked.error().to_string();
  engine::Scene scene = engine::instantiate(a);
  auto system = gi::GISystem::load(bundle, scene);
  EXPECT_TRUE(system) << system.error().to_string();
  if (!system) return {};
  auto renderer = engine::Renderer::create(scene.assets, {.width = 96, .height = 96});
  EXPECT_TRUE(renderer) << renderer.error().to_string();
  if (!renderer) return {};
  (*renderer)->set_indirect_light(system->get());
  (*renderer)->render(scene.registry, engine::find_camera(scene.registry));
  engine::ImageRgbaF img = (*renderer)->read_hdr();
  system->reset();
  return img;
}

}  // namespace

// Nothing is counted twice and nothing left out (docs/scene-format.md, "What is baked and what
// is drawn live"): by default the renderer draws the lamp live and the atlas holds the sky and
// every bounce; with --include-direct the atlas holds the lamp's direct light too and the
// renderer draws no lamp on the static surfaces. The two frames differ only in how the lamp's
// direct light is resolved (shadow maps per pixel against atlas texels): the same light over
// the frame and over each 12 x 12-pixel block. Counting the lamp or the sky twice, or leaving
// either out, moves the frame by more than its own share (the lamp lights most of the box).
TEST(OutdoorScene, IncludeDirectCountsNothingTwice) {
  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  const engine::ImageRgbaF live = cornell_frame_with_sky(false);
  const engine::ImageRgbaF baked = cornell_frame_with_sky(true);
  ASSERT_EQ(live.pixels.size(), baked.pixels.size());
  ASSERT_FALSE(live.pixels.empty());
  constexpr int kBlock = 12;
  const int blocks = live.width / kBlock;
  double sum_live = 0.0, sum_baked = 0.0, worst = 0.0;
  for (int by = 0; by < blocks; ++by)
    for (int bx = 0; bx < blocks; ++bx) {
      double l = 0.0, b = 0.0;
      for (int y = by * kBlock; y < (by + 1) * kBlock; ++y)
        for (int x = bx * kBlock; x < (bx + 1) * kBlock; ++x)
          for (int c = 0; c < 3; ++c) {
            const std::size_t i =
                4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(live.width) + static_cast<std::size_t>(x)) +
                static_cast<std::size_t>(c);
            l += static_cast<double>(live.pixels[i]);
            b += static_cast<double>(baked.pixels[i]);
          }
      sum_live += l;
      sum_baked += b;
      if (l > 0.0) worst = std::max(worst, std::fabs(b / l - 1.0));
    }
  std::printf(
      "Cornell box with its lamp under a gradient sky: frame with --include-direct / default %.4f, worst "
      "%d x %d block %.4f\n",
      sum_baked / sum_live, kBlock, kBlock, worst);
  EXPECT_NEAR(sum_baked / sum_live, 1.0, 0.04);
  EXPECT_LT(worst, 0.25);
}
