// The public bake API (gi/bake.h) as a studio's pipeline uses it: a BakeInput filled by the
// pipeline's own code from its own scene data — no engine::Scene, no registry — baked into
// a bundle that the runtime then accepts for the level the game instantiates.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {

// A pipeline's converter from its scene format (here: the file's asset, read by the
// engine's glTF loader, never instantiated) into the bakers' plain data.
gi::BakeInput pipeline_input(const engine::SceneAsset& asset) {
  gi::BakeInput in;
  in.name = fs::path(asset.source).filename().string();
  for (const engine::Mesh& m : asset.meshes) {
    gi::BakeMesh mesh{.name = m.name, .primitives = {}};
    for (const engine::Primitive& p : m.primitives)
      mesh.primitives.push_back({.positions = p.positions,
                                 .normals = p.normals,
                                 .indices = p.indices,
                                 .uv0 = p.uv0,
                                 .uv1 = p.uv1,
                                 .material = p.material});
    in.meshes.push_back(std::move(mesh));
  }
  for (const engine::Material& m : asset.materials)
    in.materials.push_back({.name = m.name,
                            .base_color = glm::vec3(m.base_color),
                            .metallic = m.metallic,
                            .roughness = m.roughness,
                            .specular = m.specular_factor,
                            .specular_color = m.specular_color_factor,
                            .emission = m.emissive,
                            .double_sided = m.double_sided,
                            .base_alpha = m.base_color.w,
                            .base_color_texture = m.base_color_texture,
                            .metallic_roughness_texture = m.metallic_roughness_texture,
                            .emissive_texture = m.emissive_texture,
                            .normal_texture = m.normal_texture,
                            .normal_scale = m.normal_scale,
                            .alpha_mode = m.alpha_mode,
                            .alpha_cutoff = m.alpha_cutoff});
  // The textures' decoded texels (the demo level's brick, wood, rug and grille).
  for (const engine::Image& i : asset.images)
    in.images.push_back({.name = i.name, .uri = i.uri, .width = i.width, .height = i.height, .rgba8 = i.rgba8});
  for (std::size_t i = 0; i < asset.nodes.size(); ++i) {
    const engine::Node& n = asset.nodes[i];
    const glm::mat4 world = gi::node_world_matrix(asset, static_cast<int>(i));
    if (n.mesh >= 0)
      in.instances.push_back({.name = n.name,
                              .mesh = static_cast<std::uint32_t>(n.mesh),
                              .object_to_world = world,
                              .mobility = n.gi.mobility == engine::Mobility::Dynamic ? gi::BakeMobility::Dynamic
                                                                                     : gi::BakeMobility::Static,
                              .deforming = n.gi.region == engine::GiRegion::Deforming,
                              .id = static_cast<std::int64_t>(i)});  // the runtime matches static meshes by node
    if (n.light >= 0)
      in.lights.push_back(
          {.name = n.name, .light = asset.lights[static_cast<std::size_t>(n.light)].light, .light_to_world = world});
  }
  return in;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "bake_api" / name;
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST(BakeApi, BakesTheDemoLevelFromPlainDataAndTheRuntimeAcceptsIt) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/demo_level.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  const gi::BakeInput input = pipeline_input(*asset);
  ASSERT_TRUE(gi::validate_bake_input(input)) << gi::validate_bake_input(input).error().to_string();

  const fs::path dir = fresh_dir("demo_level.gibake");
  std::vector<std::string> stages;
  int log_lines = 0;
  double last_fraction = -1.0;
  bool monotonic = true;
  const gi::BakeHost host{.progress =
                              [&](std::string_view stage, double f) {
                                if (stages.empty() || stages.back() != stage)
                                  stages.emplace_back(stage), last_fraction = -1.0;
                                monotonic = monotonic && f >= last_fraction && f <= 1.0;
                                last_fraction = f;
                                return true;
                              },
                          .log = [&](gi::LogLevel, std::string_view) { ++log_lines; }};
  auto report = gi::bake_bundle(input, dir, {.preset = "preview", .methods = {"light_atlas"}}, host);
  ASSERT_TRUE(report) << report.error().to_string();
  ASSERT_EQ(report->baked.size(), 1u);
  EXPECT_EQ(report->baked[0].method, "light_atlas");
  EXPECT_GT(report->baked[0].bytes, 0u);
  EXPECT_EQ(stages, std::vector<std::string>{"light atlas"});
  EXPECT_TRUE(monotonic);
  EXPECT_DOUBLE_EQ(last_fraction, 1.0);
  EXPECT_GT(log_lines, 0);
  EXPECT_FALSE(report->plan.effects.empty()) << "the plan of the demo level is reported";

  // The game's level, instantiated by the engine: the bundle of the pipeline's data fits it.
  engine::Scene scene = engine::instantiate(std::move(asset).value());
  auto system = gi::GISystem::load(dir, scene);
  ASSERT_TRUE(system) << system.error().to_string();
  EXPECT_STREQ((*system)->label(), "light atlas");
}

TEST(BakeApi, ABakeCancelledByItsHostWritesNothing) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  const fs::path dir = fresh_dir("cancelled.gibake");
  int calls = 0;
  auto report = gi::bake_bundle(pipeline_input(*asset), dir, {.preset = "preview", .methods = {"light_atlas"}},
                                {.progress = [&](std::string_view, double) { return ++calls < 3; }});
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error().kind, engine::ErrorKind::Cancelled) << report.error().to_string();
  EXPECT_EQ(calls, 3) << "no progress is reported after the host said stop";
  EXPECT_FALSE(fs::exists(dir));
}

// A re-bake that is cancelled (or fails, or is killed) half-way leaves the working bundle
// as it was: every file byte for byte, and it still loads.
TEST(BakeApi, ACancelledRebakeLeavesTheWorkingBundleIntact) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  const gi::BakeInput input = pipeline_input(*asset);
  const fs::path dir = fresh_dir("rebaked.gibake");
  ASSERT_TRUE(gi::bake_bundle(input, dir, {.preset = "preview", .methods = {"light_atlas"}}));
  const auto snapshot = [&] {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto& e : fs::directory_iterator(dir)) {
      std::ifstream in(e.path(), std::ios::binary);
      files.emplace_back(e.path().filename().string(), std::string(std::istreambuf_iterator<char>(in), {}));
    }
    std::sort(files.begin(), files.end());
    return files;
  };
  const auto before = snapshot();
  int calls = 0;
  auto report = gi::bake_bundle(
      input, dir, {.preset = "medium", .methods = {"light_atlas", "prm"}},
      {.progress = [&](std::string_view stage, double) { return stage == "light atlas" || ++calls < 2; }});
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error().kind, engine::ErrorKind::Cancelled);
  EXPECT_EQ(snapshot(), before) << "the atlas baked before the cancel did not replace the working one";
  EXPECT_FALSE(fs::exists(dir.parent_path() / ".rebaked.gibake.staging"));
  engine::Scene scene = engine::instantiate(std::move(asset).value());
  auto system = gi::GISystem::load(dir, scene);
  EXPECT_TRUE(system) << system.error().to_string();
}

TEST(BakeApi, BadInputIsRefusedNamingTheElement) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  gi::BakeInput input = pipeline_input(*asset);
  input.meshes[1].primitives[0].indices.push_back(100000);
  input.meshes[1].primitives[0].indices.push_back(0);
  input.meshes[1].primitives[0].indices.push_back(1);
  const fs::path dir = fresh_dir("bad.gibake");
  auto report = gi::bake_bundle(input, dir, {.preset = "preview"});
  ASSERT_FALSE(report);
  const std::string msg = report.error().to_string();
  EXPECT_NE(msg.find("mesh 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("100000"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(dir));

  input = pipeline_input(*asset);
  input.instances[0].object_to_world[3][0] = std::nanf("");
  report = gi::bake_bundle(input, dir, {.preset = "preview"});
  ASSERT_FALSE(report);
  EXPECT_NE(report.error().to_string().find("instance 0"), std::string::npos) << report.error().to_string();

  report = gi::bake_bundle(pipeline_input(*asset), dir, {.preset = "preview", .methods = {"photon_map"}});
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error().kind, engine::ErrorKind::Invalid);
  EXPECT_NE(report.error().to_string().find("photon_map"), std::string::npos) << report.error().to_string();
}

// Two bakes of one bundle at a time would certify each other's files: the second is refused.
TEST(BakeApi, ASecondBakeOfTheSameBundleIsRefusedWhileOneRuns) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  const gi::BakeInput input = pipeline_input(*asset);
  const fs::path dir = fresh_dir("locked.gibake");
  std::string second_error;
  auto first = gi::bake_bundle(
      input, dir, {.preset = "preview", .methods = {"light_atlas"}}, {.progress = [&](std::string_view, double) {
        if (second_error.empty()) {
          auto second = gi::bake_bundle(input, dir, {.preset = "preview", .methods = {"light_atlas"}});
          second_error = second ? "the second bake ran" : second.error().to_string();
        }
        return true;
      }});
  ASSERT_TRUE(first) << first.error().to_string();
  EXPECT_NE(second_error.find("another bake of this bundle is running"), std::string::npos) << second_error;
  // Released with the first: a third bake runs.
  EXPECT_TRUE(gi::bake_bundle(input, dir, {.preset = "preview", .methods = {"light_atlas"}}));
}

// bake_input_from(asset) resolves every node's parent chain once: world matrices equal the
// per-node product, flags inherit down the chain, and a 2^20-node chain (which took 2^40
// steps when each node walked its own chain) converts at once.
TEST(BakeApi, ParentChainsResolveOnceForAllNodes) {
  engine::SceneAsset asset;
  engine::Primitive tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.indices = {0, 1, 2};
  asset.meshes.push_back(engine::Mesh{"tri", {tri}});
  constexpr int kDepth = 1 << 20;
  asset.nodes.resize(kDepth);
  for (int i = 0; i < kDepth; ++i) {
    engine::Node& n = asset.nodes[static_cast<std::size_t>(i)];
    n.name = "n" + std::to_string(i);
    n.parent = i - 1;
    n.translation = glm::vec3(1e-6f, 0.0f, 0.0f);
  }
  asset.nodes[3].gi.region = engine::GiRegion::Deforming;
  asset.nodes[2].mesh = 0;
  asset.nodes[5].mesh = 0;
  asset.nodes[kDepth - 1].mesh = 0;
  const gi::BakeInput in = gi::bake_input_from(asset);
  ASSERT_EQ(in.instances.size(), 3u);
  EXPECT_FALSE(in.instances[0].deforming);  // node 2: above the flag
  EXPECT_TRUE(in.instances[1].deforming);   // node 5: under node 3
  EXPECT_TRUE(in.instances[2].deforming);
  for (const gi::BakeInstance& inst : {in.instances[0], in.instances[1]}) {
    const glm::mat4 expected = gi::node_world_matrix(asset, static_cast<int>(inst.id));
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_FLOAT_EQ(inst.object_to_world[c][r], expected[c][r]);
  }
  // A million float additions drift (measured 0.6%): the position is 1 m along x, roughly.
  EXPECT_NEAR(in.instances[2].object_to_world[3][0], 1e-6f * kDepth, 0.02f);
}

// A bundle remembers the textures it was baked with (issue 33): the level with one texel of
// a base colour texture changed is another level, and the runtime refuses the bundle as stale.
TEST(BakeApi, ABundleBakedWithOtherTexturesIsStale) {
  auto loaded = engine::load_gltf(GI_SOURCE_DIR "/assets/demo_level.gltf");
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  engine::SceneAsset asset = std::move(loaded).value();
  engine::Image checker{.name = "checker", .uri = "", .width = 4, .height = 4, .rgba8 = {}};
  for (int i = 0; i < 16; ++i)
    checker.rgba8.insert(checker.rgba8.end(), {200, 90, static_cast<std::uint8_t>(i * 16), 255});
  asset.images.push_back(checker);
  const int textured = asset.meshes[0].primitives[0].material;
  ASSERT_GE(textured, 0);
  asset.materials[static_cast<std::size_t>(textured)].base_color_texture.image =
      static_cast<int>(asset.images.size() - 1);
  const gi::BakeInput input = gi::bake_input_from(asset);
  ASSERT_TRUE(gi::validate_bake_input(input)) << gi::validate_bake_input(input).error().to_string();

  const fs::path dir = fresh_dir("textured_demo_level.gibake");
  auto report = gi::bake_bundle(input, dir, {.preset = "preview", .methods = {"light_atlas"}});
  ASSERT_TRUE(report) << report.error().to_string();

  engine::Scene same = engine::instantiate(engine::SceneAsset(asset));
  auto accepted = gi::GISystem::load(dir, same);
  EXPECT_TRUE(accepted) << "the textures it was baked with: " << (accepted ? "" : accepted.error().to_string());
  engine::SceneAsset changed = asset;
  changed.images.back().rgba8[5] ^= 0x40;  // one texel's green
  engine::Scene other = engine::instantiate(std::move(changed));
  auto refused = gi::GISystem::load(dir, other);
  ASSERT_FALSE(refused) << "a bundle baked with other textures must be refused";
  EXPECT_NE(refused.error().to_string().find("stale"), std::string::npos) << refused.error().to_string();
}
