// Writing the light-atlas parameterization into scene data as TEXCOORD_1: a glTF round trip
// of the Cornell box, and meshes shared by several nodes.
#include "uv/atlas_scene_writer.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace {

// The uv1 of each static node's mesh, concatenated over its primitives.
std::vector<glm::vec2> concatenated_uv1(const engine::SceneAsset& s, const engine::Node& n) {
  std::vector<glm::vec2> uv;
  for (const engine::Primitive& p : s.meshes[static_cast<std::size_t>(n.mesh)].primitives)
    uv.insert(uv.end(), p.uv1.begin(), p.uv1.end());
  return uv;
}

engine::Primitive quad(glm::vec3 origin) {
  engine::Primitive p;
  p.positions = {origin, origin + glm::vec3(1, 0, 0), origin + glm::vec3(1, 1, 0), origin + glm::vec3(0, 1, 0)};
  p.normals.assign(4, glm::vec3(0, 0, 1));
  p.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

}  // namespace

TEST(AtlasSceneWriter, CornellBoxRoundTripsUv1ThroughGltf) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  ASSERT_TRUE(asset.ok()) << asset.error().to_string();
  const auto inputs = gi::atlas_inputs_from(gi::bake_input_from(asset.value()));
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 32.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  auto with_uv1 = gi::with_atlas_uv1(asset.value(), layout.value());
  ASSERT_TRUE(with_uv1.ok()) << with_uv1.error().to_string();

  const std::filesystem::path dir = std::filesystem::path(GI_BINARY_DIR) / "atlas_scene_writer_test";
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "cornell_box_uv1.gltf";
  const engine::Status written = engine::write_gltf(with_uv1.value(), file);
  ASSERT_TRUE(written.ok()) << written.error().to_string();
  auto loaded = engine::load_gltf(file);
  ASSERT_TRUE(loaded.ok()) << loaded.error().to_string();

  ASSERT_EQ(loaded->nodes.size(), asset->nodes.size());
  std::size_t static_meshes = 0;
  for (std::size_t i = 0; i < layout->meshes.size(); ++i) {
    const gi::AtlasMeshUv& uv = layout->meshes[i];
    const engine::Node& node = loaded->nodes[static_cast<std::size_t>(uv.id)];
    ASSERT_GE(node.mesh, 0);
    for (const engine::Primitive& p : loaded->meshes[static_cast<std::size_t>(node.mesh)].primitives) {
      ASSERT_EQ(p.uv1.size(), p.positions.size()) << "TEXCOORD_1 on every static primitive";
      ASSERT_EQ(p.normals.size(), p.positions.size());
    }
    const std::vector<glm::vec2> got = concatenated_uv1(loaded.value(), node);
    ASSERT_EQ(got.size(), uv.uv1.size());
    for (std::size_t v = 0; v < got.size(); ++v) {
      EXPECT_NEAR(got[v].x, uv.uv1[v].x, 1e-6f);
      EXPECT_NEAR(got[v].y, uv.uv1[v].y, 1e-6f);
    }
    ++static_meshes;
  }
  EXPECT_EQ(static_meshes, inputs.size());

  // Same world triangles, in the same order, after splitting.
  const auto again = gi::atlas_inputs_from(gi::bake_input_from(loaded.value()));
  ASSERT_EQ(again.size(), inputs.size());
  for (std::size_t m = 0; m < inputs.size(); ++m) {
    ASSERT_EQ(again[m].indices.size(), inputs[m].indices.size());
    for (std::size_t k = 0; k < inputs[m].indices.size(); ++k) {
      const glm::vec3 a = inputs[m].positions[inputs[m].indices[k]], b = again[m].positions[again[m].indices[k]];
      EXPECT_LT(glm::length(a - b), 1e-5f);
    }
  }
  // And the loaded uv1 rebuild the same layout ordering: a rebuilt layout from the loaded scene is valid too.
  EXPECT_TRUE(gi::build_atlas_layout(again, {.texels_per_metre = 32.0f}).ok());
}

TEST(AtlasSceneWriter, SharedMeshesAreDuplicatedPerStaticNodeAndDynamicOnesLeftAlone) {
  engine::SceneAsset s;
  engine::Mesh shared{"shared", {quad(glm::vec3(0.0f))}};
  engine::Mesh folded{"folded", {quad(glm::vec3(0.0f)), quad(glm::vec3(0.0f))}};
  // The second primitive is the first one folded up by 90 degrees along x = 0..1, y = 0:
  // its vertices 0 and 1 sit on the first primitive's edge but belong to another chart.
  folded.primitives[1].positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  s.meshes = {shared, folded};
  engine::Node a{"a"}, b{"b"}, c{"c"}, d{"d"};
  a.mesh = b.mesh = c.mesh = 0;
  a.gi.mobility = engine::Mobility::Static;
  b.translation = glm::vec3(5, 0, 0);  // Unspecified counts as static
  c.gi.mobility = engine::Mobility::Dynamic;
  d.mesh = 1;
  d.translation = glm::vec3(0, 5, 0);
  s.nodes = {a, b, c, d};

  const auto inputs = gi::atlas_inputs_from(gi::bake_input_from(s));
  ASSERT_EQ(inputs.size(), 3u);
  EXPECT_EQ(inputs[0].id, 0);
  EXPECT_EQ(inputs[1].id, 1);
  EXPECT_EQ(inputs[2].id, 3);
  EXPECT_NEAR(inputs[1].positions[0].x, 5.0f, 1e-6f) << "world transform applied";
  ASSERT_EQ(inputs[2].positions.size(), 8u) << "primitives concatenated";
  EXPECT_EQ(inputs[2].indices[6], 4u) << "second primitive's indices offset by the first's vertex count";

  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  auto out = gi::with_atlas_uv1(s, layout.value());
  ASSERT_TRUE(out.ok()) << out.error().to_string();

  EXPECT_EQ(out->nodes[2].mesh, 0) << "the dynamic node keeps the original";
  EXPECT_TRUE(out->meshes[0].primitives[0].uv1.empty()) << "a mesh used by a dynamic node is left alone";
  EXPECT_NE(out->nodes[0].mesh, 0);
  EXPECT_NE(out->nodes[1].mesh, 0);
  EXPECT_NE(out->nodes[0].mesh, out->nodes[1].mesh) << "each static instance has its own mesh";
  EXPECT_EQ(out->nodes[3].mesh, 1) << "a mesh with one static user is written in place";
  EXPECT_EQ(out->meshes.size(), 4u);
  EXPECT_EQ(out->meshes[static_cast<std::size_t>(out->nodes[0].mesh)].name, "shared@a");

  const engine::Mesh& written = out->meshes[1];
  ASSERT_EQ(written.primitives.size(), 2u);
  for (const engine::Primitive& p : written.primitives) {
    EXPECT_EQ(p.uv1.size(), p.positions.size());
    EXPECT_EQ(p.uv0.size(), p.positions.size());
    EXPECT_EQ(p.normals.size(), p.positions.size());
  }
  // Two flat quads in different planes: two charts, nothing to split inside a primitive.
  const gi::AtlasMeshUv& uv = layout->meshes[2];
  EXPECT_NE(uv.triangle_chart[0], uv.triangle_chart[2]);
  EXPECT_EQ(written.primitives[0].positions.size() + written.primitives[1].positions.size(), uv.source_vertex.size());

  // A layout of another scene is rejected with a message.
  engine::SceneAsset other = s;
  other.meshes[1].primitives.pop_back();
  auto bad = gi::with_atlas_uv1(other, layout.value());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().to_string().find("does not match the scene"), std::string::npos) << bad.error().to_string();
}

TEST(AtlasSceneWriter, SplitVerticesStayInTheirPrimitive) {
  // One primitive: a cube with 8 shared vertices, every corner split into three.
  engine::SceneAsset s;
  engine::Primitive cube;
  for (int i = 0; i < 8; ++i) cube.positions.emplace_back(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
  cube.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                  2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  s.meshes = {engine::Mesh{"cube", {quad(glm::vec3(0, 0, -3)), cube}}};
  s.nodes = {engine::Node{"cube"}};
  s.nodes[0].mesh = 0;
  const auto inputs = gi::atlas_inputs_from(gi::bake_input_from(s));
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  auto out = gi::with_atlas_uv1(s, layout.value());
  ASSERT_TRUE(out.ok()) << out.error().to_string();
  const engine::Primitive& q = out->meshes[0].primitives[0];
  const engine::Primitive& c = out->meshes[0].primitives[1];
  EXPECT_EQ(q.positions.size(), 4u) << "the quad needs no split";
  EXPECT_EQ(c.positions.size(), 24u) << "8 corners x 3 faces";
  EXPECT_EQ(c.normals.size(), 0u) << "absent attributes stay absent";
  ASSERT_EQ(c.indices.size(), cube.indices.size());
  for (std::size_t k = 0; k < c.indices.size(); ++k)
    EXPECT_EQ(c.positions[c.indices[k]], cube.positions[cube.indices[k]]);
}

// The atlas's TEXCOORD_1 replaces the file's on static meshes: tangents follow the split
// vertices, and a material reading a texture from TEXCOORD_1 is refused by name.
TEST(AtlasSceneWriter, TangentsFollowTheSplitVerticesAndTexcoord1TexturesAreRefused) {
  engine::SceneAsset s;
  engine::Primitive p = quad(glm::vec3(0.0f));
  p.tangents.assign(4, glm::vec4(1, 0, 0, 1));
  p.material = 0;
  engine::Material m;
  m.name = "decal";
  m.base_color_texture.image = 0;
  s.materials = {m};
  s.images.resize(1);
  s.meshes = {engine::Mesh{"wall", {p}}};
  engine::Node n{"wall"};
  n.mesh = 0;
  s.nodes = {n};
  const auto inputs = gi::atlas_inputs_from(gi::bake_input_from(s));
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  auto out = gi::with_atlas_uv1(s, layout.value());
  ASSERT_TRUE(out.ok()) << out.error().to_string();
  const engine::Primitive& written = out->meshes[0].primitives[0];
  EXPECT_EQ(written.tangents.size(), written.positions.size());

  s.materials[0].base_color_texture.texcoord = 1;
  s.meshes[0].primitives[0].uv1 = s.meshes[0].primitives[0].uv0;
  auto refused = gi::with_atlas_uv1(s, layout.value());
  ASSERT_FALSE(refused.ok());
  const std::string message = refused.error().to_string();
  EXPECT_NE(message.find("'wall'"), std::string::npos) << message;
  EXPECT_NE(message.find("'decal'"), std::string::npos) << message;
  EXPECT_NE(message.find("TEXCOORD_1"), std::string::npos) << message;
}
