// Happy paths of engine::load_gltf on small files written by the tests themselves:
// hierarchy order, matrix decomposition, generated normals, second UV set, strips and fans,
// accessor layouts (normalized, strided, sparse), materials and images, lights with units,
// the "gi" extras, and a .glb equal to its .gltf.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/scene.h>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0u;
    const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0u;
    const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

/// Accumulates binary data for one buffer and the buffer views / accessors over it.
struct GltfBuilder {
  json doc = json::parse(R"({"asset": {"version": "2.0"}, "bufferViews": [], "accessors": []})");
  std::vector<std::uint8_t> bin;

  template <class T>
  int view(const std::vector<T>& data, int stride = 0) {
    while (bin.size() % 4 != 0) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.resize(offset + data.size() * sizeof(T));
    std::memcpy(bin.data() + offset, data.data(), data.size() * sizeof(T));
    json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(T)}};
    if (stride != 0) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int accessor(int view_index, int component_type, int count, const char* type, int byte_offset = 0,
               bool normalized = false) {
    json a = {{"bufferView", view_index},
              {"componentType", component_type},
              {"count", count},
              {"type", type},
              {"byteOffset", byte_offset}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  int floats(const std::vector<float>& data, const char* type, int components) {
    return accessor(view(data), 5126, static_cast<int>(data.size()) / components, type);
  }
  int indices(const std::vector<std::uint16_t>& data) {
    return accessor(view(data), 5123, static_cast<int>(data.size()), "SCALAR");
  }
  /// The .gltf text with the buffer as a base64 data URI.
  std::string gltf() const {
    json d = doc;
    d["buffers"] =
        json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return d.dump(1);
  }
  /// The same content as a .glb (JSON chunk + BIN chunk).
  std::vector<std::uint8_t> glb() const {
    json d = doc;
    d["buffers"] = json::array({{{"byteLength", bin.size()}}});
    std::string text = d.dump();
    while (text.size() % 4 != 0) text += ' ';
    std::vector<std::uint8_t> b = bin;
    while (b.size() % 4 != 0) b.push_back(0);
    std::vector<std::uint8_t> out;
    auto u32 = [&](std::uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    };
    u32(0x46546C67);
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + b.size()));
    u32(static_cast<std::uint32_t>(text.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), text.begin(), text.end());
    u32(static_cast<std::uint32_t>(b.size()));
    u32(0x004E4942);
    out.insert(out.end(), b.begin(), b.end());
    return out;
  }
};

fs::path test_dir() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(testing::TempDir()) / "gi_gltf_loader" / info->name();
  fs::create_directories(dir);
  return dir;
}

fs::path write_text(const std::string& name, const std::string& text) {
  const fs::path p = test_dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

fs::path write_bytes(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const fs::path p = test_dir() / name;
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return p;
}

engine::SceneAsset load(const fs::path& p, const engine::GltfLoadOptions& options = {}) {
  auto r = engine::load_gltf(p, options);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().to_string());
  return r.ok() ? std::move(r.value()) : engine::SceneAsset{};
}

/// One triangle mesh (mesh 0) in the XY plane.
GltfBuilder triangle_file() {
  GltfBuilder b;
  const int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  b.doc["meshes"] = json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", pos}}}}})}}});
  return b;
}

TEST(GltfLoader, NodesComeParentsFirstWithReindexedParents) {
  GltfBuilder b = triangle_file();
  // File order: leaf, middle, root, other root; the scene lists the roots.
  b.doc["nodes"] = json::parse(R"([
    {"name": "leaf", "mesh": 0},
    {"name": "middle", "children": [0]},
    {"name": "root", "children": [1]},
    {"name": "other"},
    {"name": "not in the scene"}])");
  b.doc["scenes"] = json::parse(R"([{"nodes": [2, 3]}])");
  b.doc["scene"] = 0;
  const auto s = load(write_text("h.gltf", b.gltf()));
  ASSERT_EQ(s.nodes.size(), 4u);
  EXPECT_EQ(s.nodes[0].name, "root");
  EXPECT_EQ(s.nodes[1].name, "middle");
  EXPECT_EQ(s.nodes[2].name, "leaf");
  EXPECT_EQ(s.nodes[3].name, "other");
  EXPECT_EQ(s.nodes[0].parent, -1);
  EXPECT_EQ(s.nodes[1].parent, 0);
  EXPECT_EQ(s.nodes[2].parent, 1);
  EXPECT_EQ(s.nodes[3].parent, -1);
  EXPECT_EQ(s.nodes[2].mesh, 0);
}

// engine::find_camera on an instantiated file: the camera node first in the file's "nodes"
// array, not the first the loader stores (parents first: "inner" under "group" comes before
// "front" there).
TEST(GltfLoader, FindCameraPicksTheFirstCameraInTheFilesNodeOrder) {
  GltfBuilder b = triangle_file();
  b.doc["cameras"] = json::parse(R"([{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
                                     {"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}])");
  b.doc["nodes"] = json::parse(R"([
    {"name": "group", "children": [3]},
    {"name": "model", "mesh": 0},
    {"name": "front", "camera": 1},
    {"name": "inner", "camera": 0}])");
  b.doc["scenes"] = json::parse(R"([{"nodes": [0, 1, 2]}])");
  engine::SceneAsset a = load(write_text("cameras.gltf", b.gltf()));
  ASSERT_EQ(a.nodes.size(), 4u);
  EXPECT_EQ(a.nodes[1].name, "inner");
  EXPECT_EQ(a.nodes[1].file_index, 3);
  EXPECT_EQ(a.nodes[3].name, "front");
  EXPECT_EQ(a.nodes[3].file_index, 2);
  const engine::Scene scene = engine::instantiate(std::move(a));
  const engine::Entity first = engine::find_camera(scene.registry);
  ASSERT_TRUE(first);
  EXPECT_EQ(scene.registry.get<engine::Name>(first).value, "front");
  EXPECT_EQ(first, scene.node_entities[3]);
}

TEST(GltfLoader, WithoutScenesAllRootsLoad) {
  GltfBuilder b = triangle_file();
  b.doc["nodes"] = json::parse(R"([{"name": "a", "children": [1]}, {"name": "b"}, {"name": "c"}])");
  const auto s = load(write_text("noscene.gltf", b.gltf()));
  ASSERT_EQ(s.nodes.size(), 3u);
  EXPECT_EQ(s.nodes[0].name, "a");
  EXPECT_EQ(s.nodes[1].name, "b");
  EXPECT_EQ(s.nodes[1].parent, 0);
  EXPECT_EQ(s.nodes[2].name, "c");
}

TEST(GltfLoader, NodeMatrixIsDecomposedToTrs) {
  const glm::vec3 t(1.5f, -2.0f, 3.0f);
  const glm::quat r = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1.0f, 2.0f, -0.5f)));
  const glm::vec3 sc(2.0f, 0.5f, 3.0f);
  const glm::mat4 m = glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), sc);
  json matrix = json::array();
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) matrix.push_back(m[c][row]);  // column-major as glTF
  }
  GltfBuilder b = triangle_file();
  b.doc["nodes"] = json::array({{{"matrix", matrix}}});
  const auto s = load(write_text("m.gltf", b.gltf()));
  ASSERT_EQ(s.nodes.size(), 1u);
  const auto& n = s.nodes[0];
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(n.translation[i], t[i], 1e-5f);
    EXPECT_NEAR(n.scale[i], sc[i], 1e-5f);
  }
  EXPECT_NEAR(std::abs(glm::dot(n.rotation, r)), 1.0f, 1e-5f);  // q and -q are the same rotation
  // Recomposed, it gives the same matrix.
  const glm::mat4 back = glm::translate(glm::mat4(1.0f), n.translation) * glm::mat4_cast(n.rotation) *
                         glm::scale(glm::mat4(1.0f), n.scale);
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) EXPECT_NEAR(back[c][row], m[c][row], 1e-5f);
  }
}

TEST(GltfLoader, TrsAndQuaternionOrderFollowGltf) {
  GltfBuilder b = triangle_file();
  // glTF rotation is [x, y, z, w]: 90 degrees about +Y.
  b.doc["nodes"] =
      json::parse(R"([{"translation": [1, 2, 3], "rotation": [0, 0.70710678, 0, 0.70710678], "scale": [4, 5, 6]}])");
  const auto s = load(write_text("trs.gltf", b.gltf()));
  ASSERT_EQ(s.nodes.size(), 1u);
  EXPECT_EQ(s.nodes[0].translation, glm::vec3(1, 2, 3));
  EXPECT_EQ(s.nodes[0].scale, glm::vec3(4, 5, 6));
  const glm::vec3 x = s.nodes[0].rotation * glm::vec3(1, 0, 0);  // +X turns to -Z
  EXPECT_NEAR(x.z, -1.0f, 1e-5f);
}

TEST(GltfLoader, MissingNormalsAreAreaWeightedSmoothNormals) {
  GltfBuilder b;
  // Vertex 0 is shared by a large triangle in the XY plane (cross product (0,0,4)) and a
  // small one in the XZ plane (cross product (0,1,0)).
  const int pos = b.floats({0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 1, 0, 0}, "VEC3", 3);
  const int idx = b.indices({0, 1, 2, 0, 3, 4});
  b.doc["meshes"] =
      json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}})}}});
  const auto s = load(write_text("n.gltf", b.gltf()));
  ASSERT_EQ(s.meshes.size(), 1u);
  const auto& p = s.meshes[0].primitives.at(0);
  ASSERT_EQ(p.normals.size(), 5u);
  const glm::vec3 expected = glm::normalize(glm::vec3(0, 1, 4));  // unweighted would be (0, .71, .71)
  EXPECT_NEAR(glm::distance(p.normals[0], expected), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::distance(p.normals[1], glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(p.normals[3], glm::vec3(0, 1, 0)), 0.0f, 1e-6f);
}

TEST(GltfLoader, NonIndexedPrimitivesGetSequentialIndices) {
  const auto s = load(write_text("seq.gltf", triangle_file().gltf()));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].primitives.at(0).indices, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(GltfLoader, Texcoord1IsLoadedWhenPresent) {
  GltfBuilder b;
  const int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  const int uv0 = b.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
  const int uv1 = b.floats({0.25f, 0.25f, 0.5f, 0.25f, 0.25f, 0.5f}, "VEC2", 2);
  b.doc["meshes"] =
      json::array({{{"primitives", json::array({
                                       {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}, {"TEXCOORD_1", uv1}}}},
                                       {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}}}},
                                   })}}});
  const auto s = load(write_text("uv.gltf", b.gltf()));
  ASSERT_EQ(s.meshes.at(0).primitives.size(), 2u);
  const auto& with = s.meshes[0].primitives[0];
  const auto& without = s.meshes[0].primitives[1];
  ASSERT_EQ(with.uv1.size(), 3u);
  EXPECT_EQ(with.uv1[1], glm::vec2(0.5f, 0.25f));
  EXPECT_EQ(with.uv0[1], glm::vec2(1.0f, 0.0f));
  EXPECT_TRUE(without.uv1.empty());
  EXPECT_EQ(without.uv0.size(), 3u);
}

TEST(GltfLoader, StripsAndFansBecomeConsistentlyWoundLists) {
  GltfBuilder b;
  // Five vertices zig-zagging along +X in the XY plane (clockwise seen from +Z).
  const int strip_pos = b.floats({0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0}, "VEC3", 3);
  // A fan around the origin, counter-clockwise seen from +Z.
  const int fan_pos = b.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0}, "VEC3", 3);
  b.doc["meshes"] =
      json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", strip_pos}}}, {"mode", 5}},
                                                {{"attributes", {{"POSITION", fan_pos}}}, {"mode", 6}},
                                                {{"attributes", {{"POSITION", fan_pos}}}, {"mode", 1}}})}}});
  const auto s = load(write_text("strip.gltf", b.gltf()));
  ASSERT_EQ(s.meshes.at(0).primitives.size(), 2u) << "the LINES primitive is skipped";
  const auto& strip = s.meshes[0].primitives[0];
  const auto& fan = s.meshes[0].primitives[1];
  // §3.7.2.1: strip triangle i = (i, i+1+i%2, i+2-i%2); fan triangle i = (i+1, i+2, 0).
  EXPECT_EQ(strip.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4}));
  EXPECT_EQ(fan.indices, (std::vector<std::uint32_t>{1, 2, 0, 2, 3, 0, 3, 4, 0}));
  for (const auto* p : {&strip, &fan}) {
    for (std::size_t t = 0; t < p->indices.size(); t += 3) {
      const glm::vec3 a = p->positions[p->indices[t]];
      const glm::vec3 n = glm::cross(p->positions[p->indices[t + 1]] - a, p->positions[p->indices[t + 2]] - a);
      EXPECT_NE(n.z, 0.0f);
      EXPECT_EQ(n.z > 0.0f, p == &fan) << "all triangles of one primitive share a winding";
    }
  }
}

TEST(GltfLoader, NormalizedStridedAndSparseAccessors) {
  GltfBuilder b;
  // Interleaved positions with a 16-byte stride: x y z + 4 bytes padding.
  const std::vector<float> interleaved = {0, 0, 0, 9, 1, 0, 0, 9, 0, 1, 0, 9};
  const int view = b.view(interleaved, 16);
  const int pos = b.accessor(view, 5126, 3, "VEC3");
  // Normalized unsigned byte texcoords (§3.11: c / 255).
  const int uv = b.accessor(b.view(std::vector<std::uint8_t>{0, 255, 51, 0, 255, 102, 0, 0}), 5121, 3, "VEC2", 0, true);
  // Normalized unsigned short TEXCOORD_1.
  const int uv1 = b.accessor(b.view(std::vector<std::uint16_t>{0, 65535, 65535, 0, 0, 0}), 5123, 3, "VEC2", 0, true);
  // Sparse: vertex 2 replaced by (0, 2, 0).
  const int sparse_indices = b.view(std::vector<std::uint16_t>{2, 0});
  const int sparse_values = b.view(std::vector<float>{0, 2, 0});
  b.doc["accessors"][static_cast<std::size_t>(pos)]["sparse"] = {
      {"count", 1},
      {"indices", {{"bufferView", sparse_indices}, {"componentType", 5123}}},
      {"values", {{"bufferView", sparse_values}}}};
  b.doc["meshes"] =
      json::array({{{"primitives",
                     json::array({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}, {"TEXCOORD_1", uv1}}}}})}}});
  const auto s = load(write_text("layout.gltf", b.gltf()));
  ASSERT_EQ(s.meshes.size(), 1u);
  const auto& p = s.meshes[0].primitives.at(0);
  ASSERT_EQ(p.positions.size(), 3u);
  EXPECT_EQ(p.positions[1], glm::vec3(1, 0, 0));
  EXPECT_EQ(p.positions[2], glm::vec3(0, 2, 0));
  EXPECT_NEAR(p.uv0[0].y, 1.0f, 1e-7f);
  EXPECT_NEAR(p.uv0[1].x, 0.2f, 1e-6f);
  EXPECT_NEAR(p.uv0[2].x, 1.0f, 1e-7f);
  EXPECT_NEAR(p.uv0[2].y, 0.4f, 1e-6f);
  EXPECT_EQ(p.uv1[0], glm::vec2(0.0f, 1.0f));
  EXPECT_EQ(p.uv1[1], glm::vec2(1.0f, 0.0f));
}

/// A 24-bit BMP (bottom-up rows, 4-byte row padding): the simplest image stb decodes.
std::vector<std::uint8_t> bmp(int w, int h, const std::vector<std::uint8_t>& rgb_top_down) {
  const int row = (w * 3 + 3) / 4 * 4;
  const std::uint32_t size = static_cast<std::uint32_t>(54 + row * h);
  std::vector<std::uint8_t> out(54, 0);
  auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
  };
  out[0] = 'B';
  out[1] = 'M';
  put32(2, size);
  put32(10, 54);
  put32(14, 40);
  put32(18, static_cast<std::uint32_t>(w));
  put32(22, static_cast<std::uint32_t>(h));
  out[26] = 1;
  out[28] = 24;
  for (int y = h - 1; y >= 0; --y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>((y * w + x) * 3);
      out.push_back(rgb_top_down[i + 2]);
      out.push_back(rgb_top_down[i + 1]);
      out.push_back(rgb_top_down[i]);
    }
    for (int pad = w * 3; pad < row; ++pad) out.push_back(0);
  }
  return out;
}

TEST(GltfLoader, MaterialsAndImages) {
  GltfBuilder b = triangle_file();
  // 1x2 image: red on top, blue below.
  write_bytes("tex.bmp", bmp(1, 2, {255, 0, 0, 0, 0, 255}));
  b.doc["images"] = json::parse(R"([{"uri": "tex.bmp", "name": "checker"}])");
  b.doc["textures"] = json::parse(R"([{"source": 0}])");
  b.doc["materials"] = json::parse(R"([{
    "name": "lamp",
    "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1], "metallicFactor": 0.2, "roughnessFactor": 0.7,
                             "baseColorTexture": {"index": 0}},
    "normalTexture": {"index": 0},
    "emissiveFactor": [1, 0.5, 0],
    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
    "doubleSided": true}])");
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  // The textures read TEXCOORD_0, which the primitive must have (else an error, issue 33).
  b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = b.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
  const fs::path path = write_text("mat.gltf", b.gltf());
  const auto s = load(path);
  ASSERT_EQ(s.materials.size(), 1u);
  const auto& m = s.materials[0];
  EXPECT_EQ(m.name, "lamp");
  EXPECT_EQ(m.base_color, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  EXPECT_FLOAT_EQ(m.metallic, 0.2f);
  EXPECT_FLOAT_EQ(m.roughness, 0.7f);
  EXPECT_EQ(m.emissive, glm::vec3(4.0f, 2.0f, 0.0f));  // factor x strength
  EXPECT_TRUE(m.double_sided);
  EXPECT_EQ(m.base_color_texture.image, 0);
  EXPECT_EQ(m.normal_texture.image, 0);
  EXPECT_EQ(m.emissive_texture.image, -1);
  EXPECT_EQ(s.meshes.at(0).primitives.at(0).material, 0);
  ASSERT_EQ(s.images.size(), 1u);
  const auto& img = s.images[0];
  EXPECT_EQ(img.uri, "tex.bmp");
  ASSERT_EQ(img.width, 1);
  ASSERT_EQ(img.height, 2);
  EXPECT_EQ(img.rgba8, (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 0, 255, 255}));  // top row first

  const auto lazy = load(path, {.load_images = false});
  ASSERT_EQ(lazy.images.size(), 1u);
  EXPECT_TRUE(lazy.images[0].rgba8.empty());
  EXPECT_EQ(lazy.materials.at(0).base_color_texture.image, 0);
}

TEST(GltfLoader, PunctualLightsAndCamerasInEngineUnits) {
  GltfBuilder b = triangle_file();
  b.doc["extensions"] = json::parse(R"({"KHR_lights_punctual": {"lights": [
    {"type": "point", "intensity": 683, "color": [1, 0.5, 0.25], "range": 12, "name": "bulb"},
    {"type": "directional", "intensity": 6830},
    {"type": "spot", "intensity": 1366, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}},
    {"type": "spot", "spot": {}}]}})");
  b.doc["cameras"] = json::parse(R"([
    {"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1, "aspectRatio": 1.5}},
    {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0, "zfar": 10}},
    {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.2, "zfar": 80}}])");
  b.doc["nodes"] = json::parse(R"([
    {"extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"extensions": {"KHR_lights_punctual": {"light": 2}}, "camera": 2},
    {"camera": 1}])");
  const auto s = load(write_text("lights.gltf", b.gltf()));
  ASSERT_EQ(s.lights.size(), 4u);
  const auto& point = s.lights[0];
  EXPECT_EQ(point.name, "bulb");
  EXPECT_EQ(point.light.type, engine::LightType::Point);
  EXPECT_NEAR(point.light.intensity, 1.0f, 1e-6f);  // 683 cd = 1 W/sr
  EXPECT_EQ(point.light.color, glm::vec3(1.0f, 0.5f, 0.25f));
  EXPECT_FLOAT_EQ(point.light.range_m, 12.0f);
  EXPECT_EQ(s.lights[1].light.type, engine::LightType::Directional);
  EXPECT_NEAR(s.lights[1].light.intensity, 10.0f, 1e-5f);  // 6830 lx = 10 W/m^2
  EXPECT_EQ(s.lights[2].light.type, engine::LightType::Spot);
  EXPECT_NEAR(s.lights[2].light.intensity, 2.0f, 1e-6f);
  EXPECT_FLOAT_EQ(s.lights[2].light.inner_cone_rad, 0.1f);
  EXPECT_FLOAT_EQ(s.lights[2].light.outer_cone_rad, 0.5f);
  EXPECT_FLOAT_EQ(s.lights[3].light.inner_cone_rad, 0.0f);  // defaults
  EXPECT_NEAR(s.lights[3].light.outer_cone_rad, 0.78539816f, 1e-6f);
  EXPECT_NEAR(s.lights[3].light.intensity, 1.0f / 683.0f, 1e-9f);
  EXPECT_EQ(s.lights[3].light.range_m, 0.0f);  // unlimited
  ASSERT_EQ(s.nodes.size(), 3u);
  EXPECT_EQ(s.nodes[0].light, 0);
  EXPECT_EQ(s.nodes[1].light, 2);
  // The orthographic camera is skipped: camera indices are remapped.
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_FLOAT_EQ(s.cameras[0].camera.yfov_rad, 0.9f);
  EXPECT_FLOAT_EQ(s.cameras[0].camera.zfar_m, 500.0f);  // absent zfar
  EXPECT_FLOAT_EQ(s.cameras[0].camera.aspect, 1.5f);
  EXPECT_FLOAT_EQ(s.cameras[1].camera.zfar_m, 80.0f);
  EXPECT_EQ(s.nodes[1].camera, 1);
  EXPECT_EQ(s.nodes[2].camera, -1);
}

TEST(GltfLoader, GiExtrasGiveMobilityMovingLightsAndAreaLights) {
  GltfBuilder b = triangle_file();
  b.doc["extensions"] =
      json::parse(R"({"KHR_lights_punctual": {"lights": [{"type": "spot", "spot": {}}, {"type": "point"}]}})");
  b.doc["nodes"] = json::parse(R"([
    {"name": "wall", "mesh": 0, "extras": {"gi": {"mobility": "static"}}},
    {"name": "crate", "mesh": 0, "extras": {"gi": {"mobility": "dynamic", "future_key": 3}, "other": 1}},
    {"name": "flashlight", "extensions": {"KHR_lights_punctual": {"light": 0}}, "extras": {"gi": {"light_moves": true}}},
    {"name": "lamp", "extensions": {"KHR_lights_punctual": {"light": 1}}, "extras": {"gi": {"light_moves": false}}},
    {"name": "panel", "translation": [0, 2, 0],
     "extras": {"gi": {"area_light": {"size_m": [0.5, 0.25], "radiance": [8, 4, 2]}, "light_moves": true}}},
    {"name": "plain", "extras": "not an object: ignored"}])");
  const auto s = load(write_text("gi.gltf", b.gltf()));
  ASSERT_EQ(s.nodes.size(), 6u);
  EXPECT_EQ(s.nodes[0].gi.mobility, engine::Mobility::Static);
  EXPECT_EQ(s.nodes[1].gi.mobility, engine::Mobility::Dynamic);
  EXPECT_EQ(s.nodes[2].gi.mobility, engine::Mobility::Unspecified);
  EXPECT_TRUE(s.lights.at(0).light.moves);
  EXPECT_FALSE(s.lights.at(1).light.moves);
  ASSERT_EQ(s.lights.size(), 3u);
  const int area = s.nodes[4].light;
  ASSERT_EQ(area, 2);
  const auto& a = s.lights[2];
  EXPECT_EQ(a.name, "panel");
  EXPECT_EQ(a.light.type, engine::LightType::Area);
  EXPECT_FLOAT_EQ(a.light.intensity, 8.0f);  // max radiance component
  EXPECT_EQ(a.light.color, glm::vec3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(a.light.area_size_m, glm::vec2(0.5f, 0.25f));
  EXPECT_TRUE(a.light.moves);
  EXPECT_EQ(s.nodes[5].light, -1);
}

TEST(GltfLoader, GlbLoadsTheSameAsGltf) {
  GltfBuilder b;
  const int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3", 3);
  const int nrm = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
  const int uv1 = b.floats({0, 0, 1, 0, 0, 1, 1, 1}, "VEC2", 2);
  const int idx = b.indices({0, 1, 2, 2, 1, 3});
  b.doc["meshes"] = json::array(
      {{{"name", "quad"},
        {"primitives", json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_1", uv1}}},
                                     {"indices", idx}}})}}});
  b.doc["nodes"] =
      json::parse(R"([{"name": "q", "mesh": 0, "translation": [1, 2, 3], "children": [1]}, {"name": "c"}])");
  const auto text = load(write_text("same.gltf", b.gltf()));
  // Saved with a .gltf extension on purpose: the loader decides by the magic.
  const auto binary = load(write_bytes("same_binary.gltf", b.glb()));
  const auto binary_ext = load(write_bytes("same.glb", b.glb()));
  for (const auto* s : {&binary, &binary_ext}) {
    ASSERT_EQ(s->meshes.size(), 1u);
    EXPECT_EQ(s->meshes[0].name, "quad");
    const auto& p = s->meshes[0].primitives.at(0);
    const auto& q = text.meshes.at(0).primitives.at(0);
    EXPECT_EQ(p.positions, q.positions);
    EXPECT_EQ(p.normals, q.normals);
    EXPECT_EQ(p.uv1, q.uv1);
    EXPECT_EQ(p.indices, q.indices);
    ASSERT_EQ(s->nodes.size(), 2u);
    EXPECT_EQ(s->nodes[0].translation, text.nodes.at(0).translation);
    EXPECT_EQ(s->nodes[1].parent, 0);
  }
  EXPECT_EQ(text.meshes.at(0).primitives.at(0).indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3}));
}

TEST(GltfLoader, SideBinFileAndSourceName) {
  GltfBuilder b = triangle_file();
  write_bytes("tri.bin", b.bin);
  json d = b.doc;
  d["buffers"] = json::array({{{"byteLength", b.bin.size()}, {"uri", "tri.bin"}}});
  const fs::path path = write_text("side.gltf", d.dump());
  const auto s = load(path);
  EXPECT_EQ(s.source, path.string());
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].primitives.at(0).positions.at(1), glm::vec3(1, 0, 0));
}

}  // namespace
