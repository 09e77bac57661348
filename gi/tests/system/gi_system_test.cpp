// The GI system on llvmpipe with the crates room: a light atlas and basis radiance fields
// from one bundle; the red crate's bounce turns the white statue pink, and each frame
// recomputes only what changed (counters).
#define GL_GLEXT_PROTOTYPES 1
#include <unistd.h>
#include <GL/glcorearb.h>
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
#include <cstdio>
#include <filesystem>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "asset_scenes.h"
#include "brf/brf_bake.h"
#include "brf/brf_io.h"
#include "brf/brf_mesh.h"
#include "gl_context.h"
#include "gl_readback.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "transport/static_scene.h"
#include "uv/atlas_scene_writer.h"

namespace {

using gltest::read_texture;

engine::Scene crates_room() { return gitest::asset_scene("crates_room.gltf"); }

// Each GPU test's start: the GL context and the crates room.
struct CratesRoomRun {
  engine::GpuContext ctx = gltest::headless_or_fail();
  engine::Scene scene = crates_room();
};

// One bundle for all tests of this process: light atlas (preview, 8 texels/m) + BRF (preview).
// ctest runs each test in its own process, in parallel: the directory is per process.
struct Bundle {
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("gi_system_test_" + std::to_string(::getpid()) + ".gibake");
  ~Bundle() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  gi::LightAtlasBake atlas;
  Bundle() {
    std::filesystem::remove_all(dir);
    engine::Scene scene = crates_room();
    gi::LightAtlasSettings s = gi::light_atlas_preset("preview").value();
    atlas = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
    EXPECT_TRUE(gi::save_light_atlas(dir, atlas, gi::bake_input_from(scene.assets)));
    const auto sources = gi::dynamic_brf_meshes(gi::bake_input_from(scene)).value();
    gi::BrfBake brf;
    brf.settings = gi::brf_preset("preview").value();
    for (const gi::BrfSource& src : sources) brf.meshes.push_back(gi::bake_brf_mesh(src, brf.settings).value());
    EXPECT_TRUE(gi::save_brf(dir, brf, gi::bake_input_from(scene.assets)));
  }
};

const Bundle& bundle() {
  static const Bundle b;
  return b;
}

void move_to(engine::Scene& scene, const char* name, glm::vec3 position) {
  const engine::Entity e = engine::find_by_name(scene.registry, name);
  scene.registry.write<engine::Transform>(e).position = position;
  engine::update_world_transforms(scene.registry);
}

TEST(GISystem, RecomputesOnlyWhatChanged) {
  CratesRoomRun run;
  engine::Scene& scene = run.scene;
  auto loaded = gi::GISystem::load(bundle().dir, scene);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  std::printf("%s\n%s", gi.label(), gi.describe().c_str());
  EXPECT_STREQ(gi.label(), "light atlas + BRF");

  // Load and the first frame (the GPU uploads) are timed apart.
  EXPECT_GT(gi.stats().load_ms, 0.0);
  EXPECT_EQ(gi.stats().first_frame_ms, 0.0);
  gi.frame();
  EXPECT_GT(gi.stats().first_frame_ms, 0.0);
  const double first_frame_ms = gi.stats().first_frame_ms;
  EXPECT_EQ(gi.stats().brf_updates, 1u);
  const std::size_t pairs = gi.stats().brf_pairs_evaluated + gi.stats().brf_pairs_culled;
  EXPECT_EQ(pairs, 5u * 4u);  // five crates
  gi.frame();
  gi.frame();
  EXPECT_EQ(gi.stats().brf_updates, 1u);
  EXPECT_EQ(gi.stats().idle_frames, 2u);
  EXPECT_EQ(gi.stats().world_composites, 1u);
  EXPECT_EQ(gi.stats().first_frame_ms, first_frame_ms) << "only the first frame is timed as such";

  // One crate moves: only the pairs with it (8) and the pairs it may stand between (of the 12
  // among the other four, those whose capsule its sphere reaches, brf_pair_occluders) get new
  // basis irradiance; the others' is reused.
  move_to(scene, "crate_3", {2.0f, 0.0f, -1.5f});
  gi.frame();
  EXPECT_EQ(gi.stats().brf_updates, 2u);
  EXPECT_EQ(gi.stats().brf_moves, 2u);
  std::printf("crate_3 moved: %zu pairs evaluated, %zu reused, %zu culled\n", gi.stats().brf_pairs_evaluated,
              gi.stats().brf_pairs_reused, gi.stats().brf_pairs_culled);
  EXPECT_GT(gi.stats().brf_pairs_reused, 0u);
  EXPECT_EQ(gi.stats().world_composites, 2u);

  // A light changes, nothing moves: new light, every evaluated pair's basis irradiance reused.
  const engine::Entity light = engine::find_by_name(scene.registry, "ceiling_light");
  ASSERT_FALSE(light.is_null());
  scene.registry.write<engine::Light>(light).intensity *= 0.5f;
  gi.frame();
  EXPECT_EQ(gi.stats().brf_updates, 3u);
  EXPECT_EQ(gi.stats().brf_moves, 2u);
  EXPECT_EQ(gi.stats().brf_pairs_reused, gi.stats().brf_pairs_evaluated);
  gi.frame();
  EXPECT_EQ(gi.stats().idle_frames, 3u);

  // Per-vertex buffers for the crates only, finite and non-negative.
  const engine::Entity crate = engine::find_by_name(scene.registry, "crate_1");
  const std::uint32_t buffer = gi.frame().vertex_irradiance_buffer(crate).gl_name;
  ASSERT_NE(buffer, 0u);
  EXPECT_FALSE(gi.frame().vertex_irradiance_buffer(engine::find_by_name(scene.registry, "statue")));
  GLint64 bytes = 0;
  glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &bytes);
  std::vector<glm::vec4> v(static_cast<std::size_t>(bytes) / sizeof(glm::vec4));
  glGetNamedBufferSubData(buffer, 0, bytes, v.data());
  float largest = 0.0f;
  for (const glm::vec4& x : v) {
    ASSERT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z));
    EXPECT_GE(std::min({x.x, x.y, x.z}), 0.0f);
    largest = std::max(largest, x.x);
  }
  EXPECT_GT(largest, 0.0f);
}

// The crate's per-vertex irradiance after one frame (vec4 per vertex; empty when it has none).
std::vector<glm::vec4> vertex_irradiance(gi::GISystem& gi, const engine::Scene& scene, const char* name) {
  const std::uint32_t buffer = gi.frame().vertex_irradiance_buffer(engine::find_by_name(scene.registry, name)).gl_name;
  if (buffer == 0) return {};
  GLint64 bytes = 0;
  glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &bytes);
  std::vector<glm::vec4> v(static_cast<std::size_t>(bytes) / sizeof(glm::vec4));
  glGetNamedBufferSubData(buffer, 0, bytes, v.data());
  return v;
}

// Hundreds of crates crowded together outgrew the GPU's 128 MiB buffer in the stress run and
// the fields turned off for every object. Here the five crates' pairs outgrow a small cap:
// the reach narrows until they fit, the host is told, and each crate keeps its nearest
// neighbours' bounce (less light than with every pair, never more: bounces only add).
TEST(GISystem, PairsBeyondTheBufferLimitNarrowTheReachInsteadOfTurningTheFieldsOff) {
  CratesRoomRun run;
  engine::Scene& scene = run.scene;
  auto full = gi::GISystem::load(bundle().dir, scene);
  ASSERT_TRUE(full) << full.error().to_string();
  const std::vector<glm::vec4> all_pairs = vertex_irradiance(**full, scene, "crate_1");
  const std::size_t pairs = (*full)->stats().brf_pairs_evaluated + (*full)->stats().brf_pairs_culled;
  EXPECT_EQ(pairs, 5u * 4u);
  EXPECT_EQ((*full)->stats().brf_reach, 1.0f);
  full->reset();

  std::vector<std::string> warnings;
  auto narrow = gi::GISystem::load(bundle().dir, scene,
                                   {.brf_pair_budget_bytes = std::size_t{64} << 10,
                                    .log = [&](gi::LogLevel, std::string_view line) { warnings.emplace_back(line); }});
  ASSERT_TRUE(narrow) << narrow.error().to_string();
  const std::vector<glm::vec4> near_pairs = vertex_irradiance(**narrow, scene, "crate_1");
  for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
  const gi::GISystem::Stats& st = (*narrow)->stats();
  EXPECT_TRUE(st.disabled.empty()) << st.disabled.front();
  EXPECT_EQ(st.brf_updates, 1u);
  EXPECT_LT(st.brf_reach, 1.0f);
  std::printf("reach x%.3f: %zu pairs with light\n", static_cast<double>(st.brf_reach), st.brf_pairs_evaluated);
  EXPECT_GT(st.brf_pairs_evaluated, 0u);
  ASSERT_EQ(near_pairs.size(), all_pairs.size());
  double sum_near = 0.0, sum_all = 0.0;
  for (std::size_t i = 0; i < near_pairs.size(); ++i) {
    ASSERT_TRUE(std::isfinite(near_pairs[i].x) && std::isfinite(near_pairs[i].y) && std::isfinite(near_pairs[i].z));
    EXPECT_LE(near_pairs[i].x, all_pairs[i].x * 1.0001f + 1e-6f) << "vertex " << i;
    sum_near += static_cast<double>(near_pairs[i].x);
    sum_all += static_cast<double>(all_pairs[i].x);
  }
  std::printf("crate_1's irradiance: %.4g with the nearest pairs, %.4g with all\n", sum_near, sum_all);
  EXPECT_GT(sum_near, 0.0);
  EXPECT_LT(sum_near, sum_all) << "the pairs beyond the narrowed reach bring no light";
  bool told = false;
  for (const std::string& w : warnings) told = told || w.find("reach narrows") != std::string::npos;
  EXPECT_TRUE(told);
}

TEST(GISystem, TheRedCrateTurnsTheStatuePink) {
  CratesRoomRun run;
  engine::Scene& scene = run.scene;
  // The statue's plinth faces +x at x = -0.85 (statue at (-1.2, 0, 1.2), half width 0.35).
  auto layout_scene =
      gi::prepare_static_scene(gi::bake_input_from(scene), bundle().atlas.layout, gi::BakeLights::None).value();
  std::vector<std::size_t> plinth;
  for (std::size_t t = 0; t < layout_scene.texels.valid.size(); ++t) {
    const glm::vec3 p = layout_scene.texels.position[t], n = layout_scene.texels.normal[t];
    if (layout_scene.texels.valid[t] != 0 && std::abs(p.x + 0.85f) < 0.02f && n.x > 0.9f && p.y < 0.4f &&
        std::abs(p.z - 1.2f) < 0.3f)
      plinth.push_back(t);
  }
  ASSERT_GT(plinth.size(), 0u);
  auto loaded = gi::GISystem::load(bundle().dir, scene);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  const int w = bundle().atlas.width, h = bundle().atlas.height;
  const auto bounce_on_plinth = [&] {
    const std::vector<glm::vec3> atlas = read_texture(gi.frame().irradiance_atlas_texture, w, h);
    glm::dvec3 sum(0.0);
    for (std::size_t t : plinth) sum += glm::dvec3(atlas[t] - bundle().atlas.irradiance[t]);
    return sum / static_cast<double>(plinth.size());
  };
  const glm::dvec3 far = bounce_on_plinth();
  move_to(scene, "crate_red", {-0.5f, 0.0f, 1.2f});  // 10 cm from the plinth
  const glm::dvec3 near = bounce_on_plinth();
  std::printf("change on the plinth (W/m^2): red crate far (%.4f, %.4f, %.4f), near (%.4f, %.4f, %.4f); base %.4f\n",
              far.x, far.y, far.z, near.x, near.y, near.z, double{bundle().atlas.irradiance[plinth[0]].x});
  // The change is the crate's red bounce minus the world light it blocks (BrfResult::static_occlusion):
  // 10 cm in front of the plinth it blocks more than its unlit side sends, so the plinth gets
  // darker, and redder.
  EXPECT_GT(near.x - near.y, 0.1);                                  // red light
  EXPECT_GT(near.x - near.y, 5.0 * std::max(far.x - far.y, 1e-6));  // from the crate that came close
  EXPECT_LT(near.y, far.y);                                         // and it blocks the world's light
}

TEST(GISystem, LoadLeavesTheScenesAssetsUnchanged) {
  engine::Scene scene = crates_room();
  const engine::SceneAsset before = scene.assets;
  std::vector<std::uint32_t> meshes_before;
  for (engine::Entity e : scene.node_entities)
    if (const auto* mr = scene.registry.try_get<engine::MeshRenderer>(e)) meshes_before.push_back(mr->mesh);
  auto loaded = gi::GISystem::load(bundle().dir, scene);
  ASSERT_TRUE(loaded) << loaded.error().to_string();

  ASSERT_EQ(scene.assets.meshes.size(), before.meshes.size());
  for (std::size_t m = 0; m < before.meshes.size(); ++m) {
    ASSERT_EQ(scene.assets.meshes[m].primitives.size(), before.meshes[m].primitives.size());
    for (std::size_t p = 0; p < before.meshes[m].primitives.size(); ++p) {
      const engine::Primitive& now = scene.assets.meshes[m].primitives[p];
      const engine::Primitive& was = before.meshes[m].primitives[p];
      EXPECT_EQ(now.positions, was.positions) << "mesh " << m;
      EXPECT_EQ(now.normals, was.normals) << "mesh " << m;
      EXPECT_EQ(now.uv0, was.uv0) << "mesh " << m;
      EXPECT_EQ(now.uv1, was.uv1) << "mesh " << m << ": no TEXCOORD_1 written into the game's scene";
      EXPECT_EQ(now.indices, was.indices) << "mesh " << m;
    }
  }
  ASSERT_EQ(scene.assets.nodes.size(), before.nodes.size());
  for (std::size_t n = 0; n < before.nodes.size(); ++n) EXPECT_EQ(scene.assets.nodes[n].mesh, before.nodes[n].mesh);
  std::vector<std::uint32_t> meshes_after;
  for (engine::Entity e : scene.node_entities)
    if (const auto* mr = scene.registry.try_get<engine::MeshRenderer>(e)) meshes_after.push_back(mr->mesh);
  EXPECT_EQ(meshes_after, meshes_before);

  // The atlas's TEXCOORD_1 goes to the renderer instead: one atlas mesh per static instance
  // the layout holds, for that node's entity and mesh.
  const std::span<const engine::AtlasMesh> atlas = (*loaded)->atlas_meshes();
  ASSERT_EQ(atlas.size(), bundle().atlas.layout.meshes.size());
  for (std::size_t i = 0; i < atlas.size(); ++i) {
    const auto node = static_cast<std::size_t>(bundle().atlas.layout.meshes[i].id);
    EXPECT_EQ(atlas[i].entity, scene.node_entities[node]);
    EXPECT_EQ(atlas[i].source_mesh, static_cast<std::uint32_t>(before.nodes[node].mesh));
    for (const engine::Primitive& p : atlas[i].mesh.primitives) EXPECT_EQ(p.uv1.size(), p.positions.size());
  }
}

// The GI system's light without its atlas meshes: for a renderer made from a scene that
// holds TEXCOORD_1 itself (how the GI was drawn when load wrote it into the scene).
struct WithoutAtlasMeshes final : engine::IndirectLightProvider {
  engine::IndirectLightProvider* gi = nullptr;
  const engine::IndirectLightFrame& frame() override { return gi->frame(); }
  const char* label() const override { return gi->label(); }
};

enum class Order { RendererFirst, LoadFirst, Uv1InTheScene };

// The crates room drawn with the GI, the renderer made before or after GISystem::load, or
// from the scene with the atlas's TEXCOORD_1 written into it.
engine::ImageRgba8 crates_room_frame(Order order) {
  engine::Scene scene = crates_room();
  engine::RenderSettings settings;
  settings.width = 96;
  settings.height = 64;
  std::unique_ptr<engine::Renderer> renderer;
  if (order == Order::RendererFirst) renderer = engine::Renderer::create(scene.assets, settings).value();
  auto loaded = gi::GISystem::load(bundle().dir, scene);
  EXPECT_TRUE(loaded) << loaded.error().to_string();
  if (!loaded) return {};
  WithoutAtlasMeshes without;
  without.gi = loaded->get();
  if (order == Order::LoadFirst) renderer = engine::Renderer::create(scene.assets, settings).value();
  if (order == Order::Uv1InTheScene) {
    auto with_uv1 = gi::with_atlas_uv1(scene.assets, bundle().atlas.layout);
    EXPECT_TRUE(with_uv1) << with_uv1.error().to_string();
    if (!with_uv1) return {};
    EXPECT_EQ(with_uv1->meshes.size(), scene.assets.meshes.size()) << "no static mesh shared by two nodes";
    renderer = engine::Renderer::create(*with_uv1, settings).value();
  }
  renderer->set_indirect_light(order == Order::Uv1InTheScene ? static_cast<engine::IndirectLightProvider*>(&without)
                                                             : loaded->get());
  renderer->render(scene.registry, engine::find_camera(scene.registry));
  return renderer->read_ldr();
}

TEST(GISystem, TheRendererMayBeCreatedBeforeOrAfterLoad) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  const engine::ImageRgba8 after = crates_room_frame(Order::LoadFirst);
  const engine::ImageRgba8 before = crates_room_frame(Order::RendererFirst);
  ASSERT_FALSE(after.pixels.empty());
  EXPECT_EQ(before.width, after.width);
  EXPECT_EQ(before.pixels, after.pixels) << "the same frame, whichever was made first";
  // ... and the frame drawn when load wrote TEXCOORD_1 into the scene, to the bit.
  EXPECT_EQ(crates_room_frame(Order::Uv1InTheScene).pixels, after.pixels);

  // And the atlas reaches the static surfaces: without the GI the frame differs.
  engine::Scene scene = crates_room();
  engine::RenderSettings settings;
  settings.width = 96;
  settings.height = 64;
  auto plain = engine::Renderer::create(scene.assets, settings).value();
  plain->render(scene.registry, engine::find_camera(scene.registry));
  EXPECT_NE(plain->read_ldr().pixels, after.pixels);
}

TEST(GISystem, ABundleOfOtherMeshesIsRejectedAsStale) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf").value();
  for (engine::Mesh& m : asset.meshes)
    if (m.name == "crate")
      for (engine::Primitive& p : m.primitives)
        for (glm::vec3& v : p.positions) v *= 1.1f;
  engine::Scene scene = engine::instantiate(std::move(asset));
  auto loaded = gi::GISystem::load(bundle().dir, scene);
  ASSERT_FALSE(loaded);
  std::printf("%s\n", loaded.error().to_string().c_str());
  EXPECT_NE(loaded.error().to_string().find("stale"), std::string::npos);
}

// The red crate made a metal (metallic 1, roughness 0.5): the bake separates its lobe, the
// system bounces it as a glossy object on the GPU, the crate it stands beside turns red on
// the facing side, and turning the metal rough makes the bundle stale.
TEST(GISystem, AMetalCrateBouncesAsAGlossyObject) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  const auto metal_room = [](float roughness) {
    auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf").value();
    for (engine::Material& m : asset.materials)
      if (m.name == "crate_red") m.metallic = 1.0f, m.roughness = roughness;
    return engine::instantiate(std::move(asset));
  };
  engine::Scene scene = metal_room(0.5f);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("gi_system_glossy_" + std::to_string(::getpid()) + ".gibake");
  std::filesystem::remove_all(dir);
  const auto sources = gi::dynamic_brf_meshes(gi::bake_input_from(scene)).value();
  gi::BrfBake brf;
  brf.settings = gi::brf_preset("preview").value();
  for (const gi::BrfSource& src : sources) {
    brf.meshes.push_back(gi::bake_brf_mesh(src, brf.settings).value());
    EXPECT_EQ(brf.meshes.back().model.glossy.has_value(), src.name == "crate_red") << src.name;
  }
  ASSERT_TRUE(gi::save_brf(dir, brf, gi::bake_input_from(scene.assets)));

  auto loaded = gi::GISystem::load(dir, scene);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  // The planner calls the crate a glossy metal; the runtime loaded its lobe's terms.
  EXPECT_NE(gi::plan(gi::bake_input_from(scene))
                .effect(gi::EffectMethod::BasisRadianceFields)
                .reason.find("glossy metal (crate_red)"),
            std::string::npos);
  EXPECT_NE(gi.describe().find("; glossy: crate_red\n"), std::string::npos) << gi.describe();
  // crate_2 stands at (-0.4, 0, -1.6), unturned: its +z face looks at where the red crate goes.
  const engine::Entity crate_2 = engine::find_by_name(scene.registry, "crate_2");
  const engine::MeshRenderer& mr = scene.registry.get<engine::MeshRenderer>(crate_2);
  const gi::BrfMesh mesh = gi::brf_mesh_from_input(gi::bake_input_from(scene.assets), mr.mesh).value();
  const auto facing_light = [&] {
    const std::uint32_t buffer = gi.frame().vertex_irradiance_buffer(crate_2).gl_name;
    std::vector<glm::vec4> v(mesh.positions.size());
    glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(v.size() * sizeof(glm::vec4)), v.data());
    glm::dvec3 sum(0.0);
    int count = 0;
    for (std::size_t j = 0; j < v.size(); ++j) {
      EXPECT_TRUE(std::isfinite(v[j].x) && std::isfinite(v[j].y) && std::isfinite(v[j].z)) << j;
      if (mesh.normals[j].z > 0.9f) sum += glm::dvec3(v[j]), ++count;
    }
    EXPECT_GT(count, 0);
    return sum / static_cast<double>(std::max(count, 1));
  };
  const glm::dvec3 far = facing_light();
  move_to(scene, "crate_red", {-0.4f, 0.0f, -0.9f});  // 20 cm in front of crate_2's +z face
  const glm::dvec3 near = facing_light();
  std::printf("crate_2's face toward the metal crate (W/m^2): far (%.4f, %.4f, %.4f), near (%.4f, %.4f, %.4f)\n", far.x,
              far.y, far.z, near.x, near.y, near.z);
  EXPECT_GT(near.x - far.x, 3.0 * std::abs(near.y - far.y));  // the metal's red reflection
  EXPECT_GT(near.x - far.x, 0.05 * far.x);
  loaded->reset();

  // The same bundle for a rough red crate: the lobe is part of the mesh hash.
  engine::Scene rough = metal_room(0.9f);
  auto stale = gi::GISystem::load(dir, rough);
  ASSERT_FALSE(stale);
  EXPECT_NE(stale.error().to_string().find("stale"), std::string::npos) << stale.error().to_string();
  std::filesystem::remove_all(dir);
}

// The corridor's door (assets/corridor.gltf, baked at 50 degrees) as an antiradiance region:
// Stats tells whether a move's solve started warm, from the previous move's solution. The
// first move after load has none (cold); the next starts from it; a move back to the baked
// pose solves nothing (not warm), and the GPU tables keep the last solution for the move after.
TEST(GISystem, ADoorMoveAfterTheFirstReportsAWarmStart) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/corridor.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  engine::Scene scene = engine::instantiate(std::move(asset.value()));
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("gi_system_warm_" + std::to_string(::getpid()) + ".gibake");
  std::filesystem::remove_all(dir);
  gi::BakeOptions options;
  options.preset = "preview";
  options.methods = {"light_atlas", "antiradiance"};
  auto bundle_written = gi::bake_bundle(gi::bake_input_from(scene), dir, options);
  ASSERT_TRUE(bundle_written) << bundle_written.error().to_string();
  auto loaded = gi::GISystem::load(dir, scene);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  gi.frame();
  EXPECT_FALSE(gi.stats().antiradiance_warm) << "nothing moved yet";

  const engine::Entity door = engine::find_by_name(scene.registry, "door");
  ASSERT_FALSE(door.is_null());
  // The pose the bake holds, bit for bit (the region compares transforms exactly).
  const glm::quat baked = scene.registry.get<engine::Transform>(door).rotation;
  const auto turn_to = [&](glm::quat rotation) {
    scene.registry.write<engine::Transform>(door).rotation = rotation;
    engine::update_world_transforms(scene.registry);
    gi.frame();
  };
  const auto open_to = [&](float degrees) { turn_to(glm::angleAxis(glm::radians(degrees), glm::vec3(0, 1, 0))); };
  open_to(100.0f);
  ASSERT_EQ(gi.stats().antiradiance_updates, 1u);
  ASSERT_FALSE(gi.stats().antiradiance_unconverged);
  EXPECT_FALSE(gi.stats().antiradiance_warm) << "the first move has no previous solution";
  const int cold_iterations = gi.stats().antiradiance_iterations;

  open_to(95.0f);
  ASSERT_EQ(gi.stats().antiradiance_updates, 2u);
  EXPECT_TRUE(gi.stats().antiradiance_warm);
  EXPECT_FALSE(gi.stats().antiradiance_unconverged);
  std::printf("door 50 -> 100 degrees: cold, %d iterations; 100 -> 95 degrees: %s, %d iterations\n", cold_iterations,
              gi.stats().antiradiance_warm ? "warm" : "cold", gi.stats().antiradiance_iterations);

  gi.frame();  // nothing moved: the stats keep the last move's
  EXPECT_EQ(gi.stats().antiradiance_updates, 2u);
  EXPECT_TRUE(gi.stats().antiradiance_warm);

  turn_to(baked);
  ASSERT_EQ(gi.stats().antiradiance_updates, 3u);
  EXPECT_EQ(gi.stats().antiradiance_iterations, 0) << "back at the baked pose: no solve";
  EXPECT_FALSE(gi.stats().antiradiance_warm);

  open_to(90.0f);
  ASSERT_EQ(gi.stats().antiradiance_updates, 4u);
  EXPECT_TRUE(gi.stats().antiradiance_warm) << "the 95-degree solution starts it";
  loaded->reset();
  std::filesystem::remove_all(dir);
}

}  // namespace
