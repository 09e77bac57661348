// The glTF loader against real third-party files (GI_EXTERNAL_ASSETS_DIR, see its
// README.md): Draco, textures, lights, second UV sets, morph targets and skins, and the
// whole glTF-Validator edge-case suite. Skips with a message when the folder is absent.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <engine/gltf.h>
#include <engine/units.h>

namespace {

namespace fs = std::filesystem;

fs::path assets() { return fs::path(GI_EXTERNAL_ASSETS_DIR); }

#define SKIP_WITHOUT_ASSETS()                                                                     \
  do {                                                                                            \
    if (!fs::is_directory(assets())) GTEST_SKIP() << "external assets not found at " << assets(); \
  } while (false)

engine::SceneAsset load_ok(const fs::path& path, engine::GltfLoadOptions options = {}) {
  auto r = engine::load_gltf(path, options);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().to_string());
  return r.ok() ? std::move(r.value()) : engine::SceneAsset{};
}

std::size_t triangle_count(const engine::SceneAsset& s) {
  std::size_t n = 0;
  for (const auto& m : s.meshes) {
    for (const auto& p : m.primitives) n += p.indices.size() / 3;
  }
  return n;
}

double total_area(const engine::Primitive& p) {
  double a = 0.0;
  for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    const glm::vec3 e1 = p.positions[p.indices[t + 1]] - p.positions[p.indices[t]];
    const glm::vec3 e2 = p.positions[p.indices[t + 2]] - p.positions[p.indices[t]];
    a += 0.5 * static_cast<double>(glm::length(glm::cross(e1, e2)));
  }
  return a;
}

std::vector<std::array<float, 3>> sorted_positions(const engine::Primitive& p) {
  std::vector<std::array<float, 3>> v;
  for (const auto& x : p.positions) v.push_back({x.x, x.y, x.z});
  std::sort(v.begin(), v.end());
  return v;
}

TEST(GltfExternalAssets, DracoBoxMatchesItsUncompressedTwin) {
  SKIP_WITHOUT_ASSETS();
  const auto draco = load_ok(assets() / "Box/glTF-Draco/Box.gltf");
  const auto plain = load_ok(assets() / "draco-google-testdata/Box/glTF/Box.gltf");
  ASSERT_EQ(draco.meshes.size(), 1u);
  ASSERT_EQ(plain.meshes.size(), 1u);
  EXPECT_EQ(triangle_count(draco), 12u);
  EXPECT_EQ(triangle_count(draco), triangle_count(plain));
  const auto& dp = draco.meshes[0].primitives.at(0);
  const auto& pp = plain.meshes[0].primitives.at(0);
  ASSERT_EQ(dp.positions.size(), pp.positions.size());
  // 14-bit-ish quantization of a unit box: a few 1e-4 of error at most.
  const float tol = 1e-3f;
  const auto a = sorted_positions(dp);
  const auto b = sorted_positions(pp);
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(a[i][static_cast<std::size_t>(c)], b[i][static_cast<std::size_t>(c)], tol) << i;
  }
  EXPECT_NEAR(total_area(dp), total_area(pp), 1e-2 * total_area(pp));
  EXPECT_EQ(dp.normals.size(), dp.positions.size());
}

TEST(GltfExternalAssets, DracoGlbBoxMatchesPlainGlb) {
  SKIP_WITHOUT_ASSETS();
  const auto draco = load_ok(assets() / "draco-google-testdata/Box/glTF_Binary/Box_Draco.glb");
  const auto plain = load_ok(assets() / "draco-google-testdata/Box/glTF_Binary/Box.glb");
  EXPECT_EQ(triangle_count(draco), triangle_count(plain));
  ASSERT_FALSE(draco.meshes.empty());
  ASSERT_FALSE(plain.meshes.empty());
  EXPECT_NEAR(total_area(draco.meshes[0].primitives.at(0)), total_area(plain.meshes[0].primitives.at(0)), 1e-2);
}

TEST(GltfExternalAssets, TruncatedDracoDataIsACleanError) {
  SKIP_WITHOUT_ASSETS();
  const fs::path dir = fs::path(testing::TempDir()) / "gi_truncated_draco";
  fs::create_directories(dir);
  const fs::path src = assets() / "Box/glTF-Draco";
  nlohmann::json doc;
  std::ifstream(src / "Box.gltf") >> doc;
  // Keep the buffer, shorten the Draco buffer view to a third: the bitstream is cut.
  const int view = doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"];
  doc["bufferViews"][static_cast<std::size_t>(view)]["byteLength"] =
      doc["bufferViews"][static_cast<std::size_t>(view)]["byteLength"].get<int>() / 3;
  fs::copy_file(src / "Box.bin", dir / "Box.bin", fs::copy_options::overwrite_existing);
  std::ofstream(dir / "Box.gltf") << doc.dump();
  auto r = engine::load_gltf(dir / "Box.gltf");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().to_string().find("Box.gltf"), std::string::npos);
  EXPECT_NE(r.error().to_string().find("Draco"), std::string::npos) << r.error().to_string();

  // Every other cut and some flipped bytes: a clean error or finite geometry, never a crash.
  nlohmann::json original;
  std::ifstream(src / "Box.gltf") >> original;
  const int full = original["bufferViews"][static_cast<std::size_t>(view)]["byteLength"].get<int>();
  std::vector<char> bin(
      (std::istreambuf_iterator<char>(*std::make_unique<std::ifstream>(src / "Box.bin", std::ios::binary))),
      std::istreambuf_iterator<char>());
  const std::size_t view_offset = doc["bufferViews"][static_cast<std::size_t>(view)].value("byteOffset", 0u);
  for (int cut = 1; cut < full; cut += 7) {
    doc["bufferViews"][static_cast<std::size_t>(view)]["byteLength"] = cut;
    std::ofstream(dir / "Box.gltf") << doc.dump();
    auto c = engine::load_gltf(dir / "Box.gltf");
    if (!c.ok()) {
      EXPECT_NE(c.error().to_string().find("Draco"), std::string::npos) << c.error().to_string();
    }
  }
  doc["bufferViews"][static_cast<std::size_t>(view)]["byteLength"] = full;
  std::ofstream(dir / "Box.gltf") << doc.dump();
  for (int flip = 0; flip < 60; ++flip) {
    std::vector<char> corrupt = bin;
    corrupt[view_offset + static_cast<std::size_t>((flip * 37) % full)] ^= static_cast<char>(1 + flip % 255);
    std::ofstream(dir / "Box.bin", std::ios::binary)
        .write(corrupt.data(), static_cast<std::streamsize>(corrupt.size()));
    auto c = engine::load_gltf(dir / "Box.gltf");
    if (c.ok()) {
      for (const auto& m : c->meshes) {
        for (const auto& p : m.primitives) {
          for (std::uint32_t i : p.indices) ASSERT_LT(i, p.positions.size());
        }
      }
    }
  }
}

TEST(GltfExternalAssets, AvocadoDracoWithTextures) {
  SKIP_WITHOUT_ASSETS();
  const fs::path path = assets() / "Avocado/glTF-Draco/Avocado.gltf";
  const auto s = load_ok(path);
  ASSERT_EQ(s.meshes.size(), 1u);
  const auto& p = s.meshes[0].primitives.at(0);
  nlohmann::json doc;
  std::ifstream(path) >> doc;
  const auto& prim = doc["meshes"][0]["primitives"][0];
  // The accessors declare the decoded counts (KHR_draco_mesh_compression).
  EXPECT_EQ(p.indices.size(), doc["accessors"][prim["indices"].get<std::size_t>()]["count"].get<std::size_t>());
  EXPECT_EQ(p.positions.size(),
            doc["accessors"][prim["attributes"]["POSITION"].get<std::size_t>()]["count"].get<std::size_t>());
  EXPECT_EQ(p.uv0.size(), p.positions.size());
  EXPECT_EQ(p.normals.size(), p.positions.size());
  ASSERT_EQ(s.materials.size(), 1u);
  const auto& m = s.materials[0];
  ASSERT_GE(m.base_color_texture.image, 0);
  ASSERT_GE(m.normal_texture.image, 0);
  ASSERT_GE(m.metallic_roughness_texture.image, 0);
  const auto& img = s.images.at(static_cast<std::size_t>(m.base_color_texture.image));
  EXPECT_GT(img.width, 0);
  EXPECT_EQ(img.rgba8.size(), static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 4u);
  for (const auto& uv : p.uv0) {
    ASSERT_TRUE(std::isfinite(uv.x) && std::isfinite(uv.y));
  }
  // Without decoding, the indices stay and the pixels are empty.
  const auto lazy = load_ok(assets() / "Avocado/glTF-Draco/Avocado.gltf", {.load_images = false});
  ASSERT_EQ(lazy.images.size(), s.images.size());
  EXPECT_TRUE(lazy.images.at(0).rgba8.empty());
  EXPECT_EQ(lazy.materials.at(0).base_color_texture.image, m.base_color_texture.image);
}

TEST(GltfExternalAssets, LightsPunctualLampConvertsCandela) {
  SKIP_WITHOUT_ASSETS();
  const fs::path path = assets() / "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf";
  const auto s = load_ok(path);
  nlohmann::json doc;
  std::ifstream(path) >> doc;
  const auto& lights = doc["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 5u);
  ASSERT_GE(s.lights.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(s.lights[i].light.type, engine::LightType::Point);
    const float cd = lights[i].value("intensity", 1.0f);
    EXPECT_NEAR(s.lights[i].light.intensity, cd / 683.0f, 1e-6f * cd) << i;
    EXPECT_EQ(s.lights[i].name, lights[i]["name"].get<std::string>());
  }
  int lit_nodes = 0;
  for (const auto& n : s.nodes) lit_nodes += n.light >= 0 ? 1 : 0;
  EXPECT_EQ(lit_nodes, 5);
}

TEST(GltfExternalAssets, MultiUvTestGltfAndGlbAgree) {
  SKIP_WITHOUT_ASSETS();
  const auto a = load_ok(assets() / "MultiUVTest/glTF/MultiUVTest.gltf");
  const auto b = load_ok(assets() / "MultiUVTest/glTF-Binary/MultiUVTest.glb");
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  ASSERT_FALSE(a.meshes.empty());
  const auto& pa = a.meshes[0].primitives.at(0);
  const auto& pb = b.meshes[0].primitives.at(0);
  ASSERT_FALSE(pa.uv1.empty());
  ASSERT_EQ(pa.uv1.size(), pa.positions.size());
  ASSERT_EQ(pa.uv1.size(), pb.uv1.size());
  for (std::size_t i = 0; i < pa.uv1.size(); ++i) {
    EXPECT_EQ(pa.uv1[i], pb.uv1[i]) << i;
  }
  EXPECT_EQ(pa.indices, pb.indices);
  EXPECT_NE(pa.uv0, pa.uv1);  // two distinct parameterizations
}

TEST(GltfExternalAssets, Vinc3rCornellBoxHasLightAtlasUvs) {
  SKIP_WITHOUT_ASSETS();
  const fs::path path = assets() / "vinc3r-cornellBox-gltf/cornellBox-2.80-Eevee-gltf.gltf";
  const auto s = load_ok(path);
  nlohmann::json doc;
  std::ifstream(path) >> doc;
  ASSERT_EQ(s.meshes.size(), doc["meshes"].size());
  std::size_t with_uv1 = 0;
  for (std::size_t m = 0; m < s.meshes.size(); ++m) {
    ASSERT_EQ(s.meshes[m].primitives.size(), doc["meshes"][m]["primitives"].size());
    for (std::size_t k = 0; k < s.meshes[m].primitives.size(); ++k) {
      const auto& p = s.meshes[m].primitives[k];
      const bool declared = doc["meshes"][m]["primitives"][k]["attributes"].contains("TEXCOORD_1");
      EXPECT_EQ(!p.uv1.empty(), declared) << s.meshes[m].name;
      if (p.uv1.empty()) continue;
      ++with_uv1;
      EXPECT_EQ(p.uv1.size(), p.positions.size());
      for (const auto& uv : p.uv1) {  // a light atlas lies in the unit square
        EXPECT_TRUE(uv.x >= -1e-4f && uv.x <= 1.0001f && uv.y >= -1e-4f && uv.y <= 1.0001f);
      }
    }
  }
  EXPECT_GE(with_uv1, 4u);  // at least the four primitives of the box itself
}

TEST(GltfExternalAssets, DracoSphereLights) {
  SKIP_WITHOUT_ASSETS();
  // sphere_lights.gltf: a spot (3 cd), a point (5 cd), a directional with a "range" (which the
  // extension defines for point and spot lights only: ignored) and a spot with an empty
  // "spot" object (defaults 0 and pi/4).
  const auto s = load_ok(assets() / "draco-google-testdata/sphere/sphere_lights.gltf");
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_EQ(s.lights[0].light.type, engine::LightType::Spot);
  EXPECT_NEAR(s.lights[0].light.intensity, 3.0f / 683.0f, 1e-7f);
  EXPECT_NEAR(s.lights[0].light.inner_cone_rad, 0.2f, 1e-6f);
  EXPECT_NEAR(s.lights[0].light.outer_cone_rad, 0.8f, 1e-6f);
  EXPECT_NEAR(s.lights[0].light.range_m, 100.0f, 1e-6f);
  EXPECT_EQ(s.lights[1].light.type, engine::LightType::Point);
  EXPECT_NEAR(s.lights[1].light.intensity, 5.0f / 683.0f, 1e-7f);
  EXPECT_EQ(s.lights[2].light.type, engine::LightType::Directional);
  EXPECT_NEAR(s.lights[2].light.intensity, 1.0f / 683.0f, 1e-7f);
  EXPECT_EQ(s.lights[2].light.range_m, 0.0f);
  EXPECT_EQ(s.lights[3].light.type, engine::LightType::Spot);
  EXPECT_NEAR(s.lights[3].light.outer_cone_rad, 0.7853982f, 1e-6f);
  EXPECT_EQ(s.lights[3].light.inner_cone_rad, 0.0f);
  // Nodes: parents before children.
  for (std::size_t i = 0; i < s.nodes.size(); ++i) EXPECT_LT(s.nodes[i].parent, static_cast<int>(i));

  for (const char* name : {"sphere.gltf", "sphere_two_tex_coords.gltf"}) {
    const auto t = load_ok(assets() / "draco-google-testdata/sphere" / name);
    EXPECT_GT(triangle_count(t), 0u) << name;
  }
  const auto two = load_ok(assets() / "draco-google-testdata/sphere/sphere_two_tex_coords.gltf");
  ASSERT_FALSE(two.meshes.empty());
  EXPECT_FALSE(two.meshes[0].primitives.at(0).uv1.empty());
}

TEST(GltfExternalAssets, MorphTargetsAndSkinsLoadTheirBaseMesh) {
  SKIP_WITHOUT_ASSETS();
  for (const char* rel :
       {"MorphPrimitivesTest/glTF-Draco/MorphPrimitivesTest.gltf", "RiggedSimple/glTF-Draco/RiggedSimple.gltf"}) {
    const auto s = load_ok(assets() / rel);
    EXPECT_GT(triangle_count(s), 0u) << rel;
    for (const auto& m : s.meshes) {
      for (const auto& p : m.primitives) {
        for (const auto& x : p.positions) ASSERT_TRUE(std::isfinite(x.x + x.y + x.z)) << rel;
      }
    }
  }
}

// Validator files that report errors but load, and why accepting them is right: the
// error is about data the engine does not read.
const std::map<std::string, std::string>& validator_allowlist() {
  static const std::map<std::string, std::string> list = {
      {"base/data/animation_data/quaternion_cubic_non_unit_values.gltf", "animations are ignored by the engine"},
      {"base/data/animation_data/invalid_input_values.gltf", "animations are ignored by the engine"},
      {"base/data/animation_data/quaternion_non_unit_values.gltf", "animations are ignored by the engine"},
      {"base/data/animation/sampler_output_count_invalid.gltf", "animations are ignored by the engine"},
      {"base/data/animation/channel_node_no_morphs.gltf", "animations are ignored by the engine"},
      {"base/data/animation/unresolved_channel_target.gltf", "animations are ignored by the engine"},
      {"base/data/animation/empty_array.gltf", "animations are ignored by the engine"},
      {"base/data/animation/unresolved_sampler_input.gltf", "animations are ignored by the engine"},
      {"base/data/animation/channel_duplicate_targets.gltf", "animations are ignored by the engine"},
      {"base/data/animation/unresolved_channel_sampler.gltf", "animations are ignored by the engine"},
      {"base/data/animation/sampler_bufferview_bytestride.gltf", "animations are ignored by the engine"},
      {"base/data/animation/sampler_too_few_cubic_frames.gltf", "animations are ignored by the engine"},
      {"base/data/animation/sampler_output_format_invalid.gltf", "animations are ignored by the engine"},
      {"base/data/animation/sampler_input_format_invalid.gltf", "animations are ignored by the engine"},
      {"base/data/animation/channel_node_matrix.gltf", "animations are ignored by the engine"},
      {"base/data/animation/sampler_input_no_bounds.gltf", "animations are ignored by the engine"},
      {"base/data/animation/unresolved_sampler_output.gltf", "animations are ignored by the engine"},
      {"ext/KHR_animation_pointer/data/animation/channel/target/missing_pointer.gltf",
       "animations are ignored by the engine"},
      {"ext/KHR_animation_pointer/data/animation/channel/target/invalid_pointer_syntax.gltf",
       "animations are ignored by the engine"},
      {"ext/KHR_animation_pointer/data/animation/channel/target/invalid_channel_target_path.gltf",
       "animations are ignored by the engine"},
      {"ext/KHR_animation_pointer/data/animation/channel/target/invalid_channel_target_node.gltf",
       "animations are ignored by the engine"},
      {"ext/KHR_animation_pointer/data/animation/channel/target/unexpected_extension.gltf",
       "animations are ignored by the engine"},
      {"base/data/node/node_weights_invalid.gltf", "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/node/weights_with_no_mesh.gltf", "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/morph_unequal_targets_count.gltf",
       "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/morph_bufferview_target_override.gltf",
       "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/morph_weights_wrong_count.gltf", "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/morph_attribute_no_base.gltf", "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/unresolved_morph_positions.gltf", "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/morph_attribute_invalid_count.gltf",
       "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/mesh/morph_position_accessor_no_bounds.gltf",
       "morph targets and weights are ignored (the base mesh loads)"},
      {"base/data/node/node_skin_without_skinned_mesh.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/node/skin_with_no_mesh.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/node/unresolved_skin.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin_data/invalid_ibm.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/mesh/unequal_joints.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/mesh_data/joints_weights_complex.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/ibm_invalid_format.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/empty_array.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/unresolved_joint.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/unresolved_skeleton.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/no_joints_in_scene.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/unresolved_ibm.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/ibm_invalid_count.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/no_common_root.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/buffer_view_bytestride.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/empty_joints_array.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/skin/skeleton_invalid.gltf", "skins are ignored (the base mesh loads)"},
      {"base/data/node/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/node/empty_children_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/mesh/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/scene/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/scene/empty_nodes_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/material/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/image/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/buffer_view/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/buffer/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/sampler/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/texture/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/camera/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/accessor/empty_array.gltf", "an empty array holds nothing the engine reads"},
      {"base/data/mesh/invalid_attribute_escaped_name.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1); morph targets and weights "
       "are ignored (the base mesh loads)"},
      {"base/data/mesh/invalid_attribute.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1); morph targets and weights "
       "are ignored (the base mesh loads)"},
      {"base/data/mesh/invalid_indexed_attribute.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1); morph targets and weights "
       "are ignored (the base mesh loads)"},
      {"base/data/mesh/accessor_unequal_count.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1)"},
      {"base/data/mesh/accessor_unaligned.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1)"},
      {"base/data/mesh/accessor_without_bytestride.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1)"},
      {"base/data/mesh/accessor_attribute_uint32.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1)"},
      {"base/data/mesh_data/colors_non_clamped.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1)"},
      {"base/data/mesh/position_accessor_invalid_format.gltf",
       "mesh not used by any node: it loads empty with a warning (used meshes get this checked)"},
      {"base/data/mesh/indices_invalid_format.gltf",
       "mesh not used by any node: it loads empty with a warning (used meshes get this checked)"},
      {"base/data/mesh/bufferview_target_override.gltf",
       "mesh not used by any node: it loads empty with a warning (used meshes get this checked)"},
      {"base/data/mesh/indices_bytestride.gltf",
       "mesh not used by any node: it loads empty with a warning (used meshes get this checked)"},
      {"base/data/mesh_data/index_buffer_oob.gltf",
       "mesh not used by any node: it loads empty with a warning (used meshes get this checked)"},
      {"base/data/mesh/position_accessor_no_bounds.gltf", "accessor min/max bounds are not used by the engine"},
      {"base/data/mesh/uv.gltf", "material texCoord sets are not used (textures are sampled with TEXCOORD_0)"},
      {"ext/KHR_texture_transform/data/textureInfo/uv_sets.gltf",
       "material texCoord sets are not used (textures are sampled with TEXCOORD_0)"},
      {"base/data/asset/min_version_invalid.gltf", "asset.minVersion is informational"},
      {"base/data/root/extensions_non_objects.gltf", "extension data the engine does not read"},
      {"base/data/root/undefined_used_extensions.gltf", "extension data the engine does not read"},
      {"base/data/root/duplicate_extension_entry.gltf", "extension data the engine does not read"},
      {"base/data/root/extensions_undeclared_wrong_pointer.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_dispersion/data/material/out_of_range.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_dispersion/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_specular/data/material/unexpected_extension.gltf",
       "the extension's factors are read wherever they appear (the validator wants it declared)"},
      {"ext/KHR_materials_emissive_strength/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_ior/data/material/out_of_range.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_ior/data/material/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_iridescence/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_anisotropy/data/material/no_tangent_space.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_anisotropy/data/material/out_of_range.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_anisotropy/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_node_visibility/data/node/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_pbrSpecularGlossiness/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/variant/empty_array.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/variant/invalid_name.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/variant/empty_object.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/primitive/non_unique.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/primitive/unresolved_references.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/primitive/empties.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/primitive/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_variants/data/primitive/dependency.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_sheen/data/material/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_volume/data/material/out_of_range.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_volume/data/material/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_clearcoat/data/material/no_tangent_space.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_clearcoat/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_materials_transmission/data/material/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/KHR_lights_punctual/data/node/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/KHR_texture_transform/data/textureInfo/unexpected_extension.gltf",
       "extension data the engine does not read"},
      {"ext/EXT_texture_webp/data/image/undeclared_extension.gltf", "extension data the engine does not read"},
      {"ext/EXT_texture_webp/data/texture/undeclared_extension.gltf", "extension data the engine does not read"},
      {"ext/EXT_texture_webp/data/texture/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/EXT_texture_webp/data/texture/unresolved_source.gltf", "extension data the engine does not read"},
      {"ext/KHR_materials_unlit/data/material/unexpected_extension.gltf", "extension data the engine does not read"},
      {"ext/KHR_mesh_quantization/data/primitive/non_required.gltf", "extension data the engine does not read"},
      {"ext/KHR_mesh_quantization/data/primitive/unexpected_extension.gltf", "extension data the engine does not read"},
      {"base/data/image/not_found.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/image/invalid_data_uri_mime_type.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/image/invalid_uri_scheme.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/image/invalid_image_data.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/image/png_eos.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/image/buffer_view_bytestride.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/image/missing_mime_type_buffer_view.gltf",
       "image not used by any material: only used images must load (others are warned about)"},
      {"base/data/mesh_data/normals_tangents_non_unit_invalid_sign.gltf",
       "a vertex attribute the engine does not read (only POSITION, NORMAL, TEXCOORD_0/1); mesh not used by any node: "
       "it loads empty with a warning (used meshes get this checked); normals are renormalized on load"},
      {"base/data/mesh_data/index_buffer_primitive_restart.gltf",
       "the restart value is below the vertex count, so it is a valid vertex index"},
      {"base/data/buffer_view/invalid_stride_wrong_target.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/buffer_view/invalid_stride_too_big.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor_data/invalid_elements_float.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor/small_stride.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor/matrix_alignment.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor/byteoffset_no_bufferview.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor/float_normalized.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor/invalid_sparse_count_and_stride.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/accessor/alignment.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked)"},
      {"base/data/buffer/no_bin_chunk.glb",
       "buffer never read: buffers without loadable data are an error only when read"},
      {"base/data/buffer/invalid_uri_data.glb",
       "buffer never read: buffers without loadable data are an error only when read"},
      {"base/data/buffer/invalid_uri_data.gltf",
       "buffer never read: buffers without loadable data are an error only when read"},
      {"base/data/buffer/invalid_uri_data_mime.gltf",
       "buffer never read: buffers without loadable data are an error only when read"},
      {"base/data/accessor_data/out_of_range_elements_sint16.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked); accessor min/max bounds are not "
       "used by the engine"},
      {"base/data/accessor_data/out_of_range_elements_uint8.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked); accessor min/max bounds are not "
       "used by the engine"},
      {"base/data/accessor_data/out_of_range_elements_float.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked); accessor min/max bounds are not "
       "used by the engine"},
      {"base/data/accessor_data/out_of_range_elements_uint16.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked); accessor min/max bounds are not "
       "used by the engine"},
      {"base/data/accessor_data/out_of_range_elements_uint32.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked); accessor min/max bounds are not "
       "used by the engine"},
      {"base/data/accessor_data/out_of_range_elements_sint8.gltf",
       "accessor or buffer view not read by any mesh (read ones are bounds-checked); accessor min/max bounds are not "
       "used by the engine"},
      {"base/data/camera/extra_type.gltf", "orthographic cameras are skipped; the perspective parameters are valid"},
      {"base/data/camera/orthographic_xy.gltf",
       "orthographic cameras are skipped; the perspective parameters are valid"},
      {"base/data/camera/orthographic_z.gltf",
       "orthographic cameras are skipped; the perspective parameters are valid"},
      {"ext/EXT_texture_webp/data/texture/invalid_image_mime_type.gltf",
       "extension data the engine does not read; image not used by any material: only used images must load (others "
       "are warned about)"},
  };
  return list;
}

// Files the validator accepts (a warning only) that the engine rejects on purpose.
const std::map<std::string, std::string>& validator_valid_but_rejected() {
  static const std::map<std::string, std::string> list = {
      {"ext/KHR_lights_punctual/data/light/unknown_type.gltf",
       "an unknown light type cannot be lit correctly; the project's rule is an error naming the light"},
      {"base/data/root/unused_objects.gltf",
       "a mesh used by node 0 reads a buffer with no uri: its geometry is not in the file"},
      {"base/data/root/named_objects.gltf",
       "a mesh used by a node reads a buffer with no uri: its geometry is not in the file"},
      {"base/data/material/valid.gltf",
       "its textures read TEXCOORD_2..4: the engine's vertices carry two UV sets, so a texCoord above 1 is an "
       "error naming the material (issue 33), not a texture silently read from the wrong set"},
  };
  return list;
}

// KHR_materials_specular feeds the one BRDF (engine/gltf_brdf.h), so out-of-range factors
// are refused naming the material, not silently clamped.
TEST(GltfExternalAssets, SpecularFactorsOutOfRangeAreRefused) {
  SKIP_WITHOUT_ASSETS();
  const fs::path p =
      assets() / "edge-cases/glTF-Validator-test/ext/KHR_materials_specular/data/material/out_of_range.gltf";
  auto r = engine::load_gltf(p);
  ASSERT_FALSE(r.ok());
  const std::string e = r.error().to_string();
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("material 0 KHR_materials_specular: specularFactor must be in [0, 1]"), std::string::npos) << e;
}

TEST(GltfExternalAssets, ValidatorSuiteNeverCrashesAndRejectsInvalidFiles) {
  SKIP_WITHOUT_ASSETS();
  const fs::path root = assets() / "edge-cases/glTF-Validator-test";
  ASSERT_TRUE(fs::is_directory(root)) << root;
  int valid_loaded = 0;
  int invalid_rejected = 0;
  int invalid_allowed = 0;
  int valid_rejected = 0;
  std::vector<std::string> problems;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const fs::path& p = entry.path();
    if (!entry.is_regular_file() || (p.extension() != ".gltf" && p.extension() != ".glb")) continue;
    const std::string rel = fs::relative(p, root).generic_string();
    std::ifstream report_file(p.string() + ".report.json");
    if (!report_file) continue;  // not a test case (e.g. a referenced resource)
    nlohmann::json report;
    report_file >> report;
    const int errors = report["issues"]["numErrors"].get<int>();
    auto r = engine::load_gltf(p, {.load_images = true});
    if (errors == 0) {
      if (r.ok()) {
        ++valid_loaded;
      } else if (validator_valid_but_rejected().count(rel) != 0) {
        ++valid_rejected;
        EXPECT_NE(r.error().to_string().find(p.string()), std::string::npos) << r.error().to_string();
      } else {
        problems.push_back("valid file rejected: " + r.error().to_string());
      }
      continue;
    }
    if (!r.ok()) {
      if (r.error().to_string().find(p.string()) == std::string::npos) {
        problems.push_back("error does not name the file: " + r.error().to_string());
      }
      ++invalid_rejected;
    } else if (validator_allowlist().count(rel) != 0) {
      ++invalid_allowed;
    } else {
      problems.push_back("invalid file accepted: " + rel);
    }
  }
  std::printf(
      "glTF-Validator suite: %d valid loaded, %d invalid rejected, %d invalid accepted by allowlist, "
      "%d valid rejected on purpose\n",
      valid_loaded, invalid_rejected, invalid_allowed, valid_rejected);
  for (const auto& s : problems) ADD_FAILURE() << s;
  EXPECT_GT(valid_loaded + invalid_rejected, 100);
}

}  // namespace
