// gi::with_light_atlas_uv1 (gi/light_atlas_uv.h, gi-bake --export-uv1): the exported scene
// carries exactly the TEXCOORD_1 the runtime gives the static meshes from a bundle baked
// from the original scene, and laying out the exported file again gives the same atlas.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>
#include <gi/light_atlas_uv.h>

#include <algorithm>
#include <filesystem>

namespace fs = std::filesystem;

namespace {

const fs::path kOut = fs::path(GI_BINARY_DIR) / "test_output" / "light_atlas_uv";

engine::SceneAsset load(const fs::path& path) {
  auto asset = engine::load_gltf(path);
  EXPECT_TRUE(asset) << asset.error().to_string();
  return asset ? std::move(asset).value() : engine::SceneAsset{};
}

}  // namespace

TEST(LightAtlasUv, ExportedFileHasTheUv1TheRuntimeGivesTheStaticMeshes) {
  const fs::path scene_path = fs::path(GI_SOURCE_DIR) / "assets" / "crates_room.gltf";
  const engine::SceneAsset original = load(scene_path);
  auto uv = gi::with_light_atlas_uv1(original, {.preset = "preview"});
  ASSERT_TRUE(uv) << uv.error().to_string();
  EXPECT_GT(uv->width, 0);
  EXPECT_GT(uv->charts, 0u);
  fs::create_directories(kOut);
  const fs::path exported_path = kOut / "crates_room_uv1.gltf";
  ASSERT_TRUE(engine::write_gltf(uv->scene, exported_path));
  const engine::SceneAsset exported = load(exported_path);

  // What the runtime does with a bundle baked from the original scene.
  const fs::path bundle = kOut / "crates_room.gibake";
  fs::remove_all(bundle);
  auto baked =
      gi::bake_bundle(gi::bake_input_from(original), bundle, {.preset = "preview", .methods = {"light_atlas"}});
  ASSERT_TRUE(baked) << baked.error().to_string();
  engine::Scene runtime = engine::instantiate(original);
  auto system = gi::GISystem::load(bundle, runtime);
  ASSERT_TRUE(system) << system.error().to_string();

  // The runtime leaves the scene as it was and hands the renderer, per static node, its mesh
  // with TEXCOORD_1 (GISystem::atlas_meshes): the exported file's mesh of that node.
  const std::span<const engine::AtlasMesh> atlas = (*system)->atlas_meshes();
  ASSERT_FALSE(atlas.empty());
  std::size_t with_uv1 = 0;
  for (const engine::AtlasMesh& am : atlas) {
    const auto node_it = std::find(runtime.node_entities.begin(), runtime.node_entities.end(), am.entity);
    ASSERT_NE(node_it, runtime.node_entities.end());
    const auto n = static_cast<std::size_t>(node_it - runtime.node_entities.begin());
    ASSERT_EQ(am.source_mesh, static_cast<std::uint32_t>(original.nodes[n].mesh));
    ASSERT_GE(exported.nodes[n].mesh, 0) << exported.nodes[n].name;
    const engine::Mesh& file_mesh = exported.meshes[static_cast<std::size_t>(exported.nodes[n].mesh)];
    const auto& a = file_mesh.primitives;
    const auto& b = am.mesh.primitives;
    ASSERT_EQ(a.size(), b.size()) << file_mesh.name;
    for (std::size_t p = 0; p < a.size(); ++p) {
      EXPECT_EQ(a[p].indices, b[p].indices) << file_mesh.name;
      ASSERT_EQ(a[p].uv1.size(), b[p].uv1.size()) << file_mesh.name;
      for (std::size_t v = 0; v < a[p].uv1.size(); ++v) ASSERT_EQ(a[p].uv1[v], b[p].uv1[v]) << file_mesh.name;
      with_uv1 += a[p].uv1.empty() ? 0 : 1;
    }
  }
  EXPECT_GT(with_uv1, 0u);
  for (std::size_t n = 0; n < exported.nodes.size(); ++n) {
    EXPECT_EQ(exported.nodes[n].mesh, uv->scene.nodes[n].mesh) << exported.nodes[n].name;
    if (exported.nodes[n].mesh >= 0 && exported.nodes[n].gi.mobility == engine::Mobility::Static) {
      EXPECT_FALSE(exported.meshes[static_cast<std::size_t>(exported.nodes[n].mesh)].primitives[0].uv1.empty())
          << exported.nodes[n].name;
    }
  }
  system->reset();
}

TEST(LightAtlasUv, LayingOutTheExportedFileAgainGivesTheSameAtlas) {
  const engine::SceneAsset original = load(fs::path(GI_SOURCE_DIR) / "assets" / "cornell_box.gltf");
  auto first = gi::with_light_atlas_uv1(original, {.texels_per_metre = 48.0f});
  ASSERT_TRUE(first) << first.error().to_string();
  fs::create_directories(kOut);
  const fs::path path = kOut / "cornell_box_uv1.glb";
  ASSERT_TRUE(engine::write_gltf(first->scene, path, {.binary = true}));
  auto again = gi::with_light_atlas_uv1(load(path), {.texels_per_metre = 48.0f});
  ASSERT_TRUE(again) << again.error().to_string();
  EXPECT_EQ(again->width, first->width);
  EXPECT_EQ(again->height, first->height);
  EXPECT_EQ(again->charts, first->charts);
  EXPECT_EQ(again->texels_per_metre, first->texels_per_metre);
  ASSERT_EQ(again->scene.meshes.size(), first->scene.meshes.size());
  for (std::size_t m = 0; m < first->scene.meshes.size(); ++m)
    for (std::size_t p = 0; p < first->scene.meshes[m].primitives.size(); ++p)
      EXPECT_EQ(again->scene.meshes[m].primitives[p].uv1, first->scene.meshes[m].primitives[p].uv1)
          << first->scene.meshes[m].name;
}

TEST(LightAtlasUv, AnUnknownPresetIsRefusedWithItsName) {
  const engine::SceneAsset original = load(fs::path(GI_SOURCE_DIR) / "assets" / "cornell_box.gltf");
  auto uv = gi::with_light_atlas_uv1(original, {.preset = "ultra"});
  ASSERT_FALSE(uv);
  EXPECT_NE(uv.error().to_string().find("ultra"), std::string::npos) << uv.error().to_string();
}
