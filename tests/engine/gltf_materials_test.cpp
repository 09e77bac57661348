// The loader's materials as artists make them (issue 33): alphaMode / alphaCutoff, the
// normal texture's scale, samplers, KHR_texture_transform, TEXCOORD sets, and the safety of
// image URIs and decode budgets. Errors name the file and the image or material.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <engine/gltf.h>
#include <engine/image.h>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0u) |
                            (i + 2 < bytes.size() ? bytes[i + 2] : 0u);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

fs::path dir() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  fs::path d = fs::path(testing::TempDir()) / "gi_gltf_materials" / info->name();
  fs::create_directories(d);
  return d;
}

/// A grey size x size PNG at `path`.
void write_png(const fs::path& path, int size) {
  engine::ImageRgba8 img;
  img.width = img.height = size;
  img.pixels.assign(static_cast<std::size_t>(size * size) * 4, 128);
  ASSERT_TRUE(engine::save_png(path, img).ok());
}

/// One triangle with POSITION and TEXCOORD_0 (and TEXCOORD_1 when `uv1`), material 0 using
/// image 0 ("tex.png", 4x4, written next to the file) as its base colour texture.
json textured_doc(bool uv1 = false) {
  std::vector<float> data = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* uv */ 0, 0, 1, 0, 0, 1};
  std::vector<std::uint8_t> bin(data.size() * 4);
  std::memcpy(bin.data(), data.data(), bin.size());
  json d = json::parse(R"({"asset": {"version": "2.0"},
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
    "meshes": [{"name": "leaves", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
    "images": [{"uri": "tex.png"}], "textures": [{"source": 0}],
    "materials": [{"name": "leaf", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  if (uv1) d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = 1;
  d["buffers"] =
      json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
  return d;
}

fs::path write_doc(const json& d, const std::string& name = "scene.gltf") {
  const fs::path p = dir() / name;
  std::ofstream(p) << d.dump();
  write_png(dir() / "tex.png", 4);
  return p;
}

/// Loads `path`, expects an error naming the file and containing every `needles` entry.
void expect_error(const fs::path& path, std::initializer_list<const char*> needles,
                  const engine::GltfLoadOptions& options = {}) {
  auto r = engine::load_gltf(path, options);
  ASSERT_FALSE(r.ok()) << path << " loaded but should not";
  const std::string msg = r.error().to_string();
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  for (const char* n : needles) EXPECT_NE(msg.find(n), std::string::npos) << "missing '" << n << "' in: " << msg;
}

TEST(GltfMaterials, DefaultsAreOpaqueRepeatLinearMipmapped) {
  auto r = engine::load_gltf(write_doc(textured_doc()));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  const engine::Material& m = r->materials.at(0);
  EXPECT_EQ(m.alpha_mode, engine::AlphaMode::Opaque);
  EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.5f);
  EXPECT_FLOAT_EQ(m.normal_scale, 1.0f);
  const engine::TextureSampler& s = m.base_color_texture.sampler;
  EXPECT_EQ(s.wrap_s, engine::TextureWrap::Repeat);
  EXPECT_EQ(s.wrap_t, engine::TextureWrap::Repeat);
  EXPECT_TRUE(s.mag_linear && s.min_linear && s.mipmaps);
  EXPECT_EQ(m.base_color_texture.transform.scale, glm::vec2(1.0f));
}

TEST(GltfMaterials, AlphaModeCutoffAndNormalScaleAreRead) {
  json d = textured_doc();
  d["materials"][0]["alphaMode"] = "MASK";
  d["materials"][0]["alphaCutoff"] = 0.25;
  d["materials"][0]["normalTexture"] = {{"index", 0}, {"scale", 0.5}};
  auto r = engine::load_gltf(write_doc(d));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_EQ(r->materials[0].alpha_mode, engine::AlphaMode::Mask);
  EXPECT_FLOAT_EQ(r->materials[0].alpha_cutoff, 0.25f);
  EXPECT_FLOAT_EQ(r->materials[0].normal_scale, 0.5f);
  EXPECT_EQ(r->materials[0].normal_texture.image, 0);
  d["materials"][0]["alphaMode"] = "BLEND";
  r = engine::load_gltf(write_doc(d));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_EQ(r->materials[0].alpha_mode, engine::AlphaMode::Blend);
}

TEST(GltfMaterials, BadAlphaModeAndCutoffAreErrors) {
  json d = textured_doc();
  d["materials"][0]["alphaMode"] = "CUTOUT";
  expect_error(write_doc(d), {"material 0 'leaf'", "alphaMode 'CUTOUT'"});
  d["materials"][0]["alphaMode"] = "MASK";
  d["materials"][0]["alphaCutoff"] = -0.5;
  expect_error(write_doc(d, "negative.gltf"), {"material 0 'leaf'", "alphaCutoff"});
}

TEST(GltfMaterials, SamplerWrapAndFiltersAreRead) {
  json d = textured_doc();
  d["samplers"] = json::parse(R"([{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728, "minFilter": 9728}])");
  d["textures"][0]["sampler"] = 0;
  auto r = engine::load_gltf(write_doc(d));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  const engine::TextureSampler& s = r->materials[0].base_color_texture.sampler;
  EXPECT_EQ(s.wrap_s, engine::TextureWrap::ClampToEdge);
  EXPECT_EQ(s.wrap_t, engine::TextureWrap::MirroredRepeat);
  EXPECT_FALSE(s.mag_linear);
  EXPECT_FALSE(s.min_linear);
  EXPECT_FALSE(s.mipmaps);
  d["samplers"][0] = json::parse(R"({"minFilter": 9985})");  // LINEAR_MIPMAP_NEAREST
  r = engine::load_gltf(write_doc(d, "mip.gltf"));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_TRUE(r->materials[0].base_color_texture.sampler.min_linear);
  EXPECT_TRUE(r->materials[0].base_color_texture.sampler.mipmaps);
  d["samplers"][0] = json::parse(R"({"wrapS": 12345})");
  expect_error(write_doc(d, "badwrap.gltf"), {"sampler 0", "wrapS 12345"});
}

TEST(GltfMaterials, TextureTransformAndItsTexCoordOverrideAreRead) {
  json d = textured_doc(true);
  d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = json::parse(
      R"({"KHR_texture_transform": {"offset": [0.25, 0.5], "rotation": 0.5, "scale": [2, 3], "texCoord": 1}})");
  d["extensionsUsed"] = {"KHR_texture_transform"};
  auto r = engine::load_gltf(write_doc(d));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  const engine::TextureRef& t = r->materials[0].base_color_texture;
  EXPECT_EQ(t.texcoord, 1);
  EXPECT_EQ(t.transform.offset, glm::vec2(0.25f, 0.5f));
  EXPECT_FLOAT_EQ(t.transform.rotation_rad, 0.5f);
  EXPECT_EQ(t.transform.scale, glm::vec2(2.0f, 3.0f));
}

// The extension's README example: offset [0, 1], rotation pi/2, scale 0.5 "utilizes only the
// lower left quadrant of the source image, rotated clockwise 90 degrees" (v points down).
TEST(GltfMaterials, TextureTransformRotatesAsTheExtensionsExampleSays) {
  const engine::TextureTransform t{{0.0f, 1.0f}, 1.57079632679f, {0.5f, 0.5f}};
  for (const glm::vec2 uv : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0, 1), glm::vec2(1, 1)}) {
    const glm::vec2 out = engine::transformed_uv(t, uv);
    EXPECT_GE(out.x, -1e-6f);
    EXPECT_LE(out.x, 0.5f + 1e-6f);
    EXPECT_GE(out.y, 0.5f - 1e-6f);
    EXPECT_LE(out.y, 1.0f + 1e-6f);
  }
  // uv (1, 0) (the right edge's top) comes from image (0, 0.5): the left edge's middle.
  const glm::vec2 right_top = engine::transformed_uv(t, {1.0f, 0.0f});
  EXPECT_NEAR(right_top.x, 0.0f, 1e-6f);
  EXPECT_NEAR(right_top.y, 0.5f, 1e-6f);
}

TEST(GltfMaterials, TexCoordSetThePrimitiveLacksNamesMaterialAndMesh) {
  json d = textured_doc(false);
  d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 1;
  expect_error(write_doc(d), {"mesh 0 'leaves' primitive 0", "material 0 'leaf'", "TEXCOORD_1"});
}

TEST(GltfMaterials, TexCoordBeyondOneIsUnsupported) {
  json d = textured_doc(true);
  d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 2;
  expect_error(write_doc(d), {"material 0 'leaf' baseColorTexture", "texCoord 2 is not supported"});
}

TEST(GltfMaterials, ImageUriLeavingTheFolderIsRefused) {
  const fs::path outside = dir() / "outside.png";
  write_png(outside, 4);
  fs::create_directories(dir() / "level");
  json d = textured_doc();
  d["images"][0]["uri"] = "../outside.png";
  const fs::path p = dir() / "level" / "scene.gltf";
  std::ofstream(p) << d.dump();
  expect_error(p, {"image 0 '../outside.png'", "leaves the scene's folder", "allow_uris_outside_folder"});
  d["images"][0]["uri"] = "sub/%2E%2E/%2e%2e/outside.png";  // percent-encoded dots climb too
  std::ofstream(p) << d.dump();
  expect_error(p, {"image 0", "leaves the scene's folder"});
  d["images"][0]["uri"] = outside.string();  // absolute
  std::ofstream(p) << d.dump();
  expect_error(p, {"absolute path"});
  // Allowed explicitly, it loads.
  engine::GltfLoadOptions allow;
  allow.allow_uris_outside_folder = true;
  d["images"][0]["uri"] = "../outside.png";
  std::ofstream(p) << d.dump();
  auto r = engine::load_gltf(p, allow);
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_EQ(r->images[0].width, 4);
  // A '..' that stays inside the folder is fine.
  fs::create_directories(dir() / "level" / "textures");
  write_png(dir() / "level" / "inside.png", 4);
  d["images"][0]["uri"] = "textures/../inside.png";
  std::ofstream(p) << d.dump();
  EXPECT_TRUE(engine::load_gltf(p).ok());
}

TEST(GltfMaterials, ImageOverThePixelBudgetIsRefusedBeforeDecoding) {
  json d = textured_doc();
  const fs::path p = write_doc(d);
  write_png(dir() / "tex.png", 64);  // 4096 pixels
  engine::GltfLoadOptions options;
  options.limits.max_image_pixels = 4000;
  expect_error(p, {"image 0 'tex.png'", "4096 pixels", "max_image_pixels"}, options);
  options.limits.max_image_pixels = 4096;
  EXPECT_TRUE(engine::load_gltf(p, options).ok());
}

TEST(GltfMaterials, ImagesOverTheSceneBudgetAreRefused) {
  json d = textured_doc();
  d["images"].push_back({{"uri", "second.png"}});
  d["textures"].push_back({{"source", 1}});
  d["materials"][0]["emissiveTexture"] = {{"index", 1}};
  const fs::path p = write_doc(d);
  write_png(dir() / "tex.png", 32);     // 4096 bytes decoded
  write_png(dir() / "second.png", 32);  // 4096 more
  engine::GltfLoadOptions options;
  options.limits.max_scene_image_bytes = 6000;
  expect_error(p, {"image 1 'second.png'", "8192 bytes", "max_scene_image_bytes"}, options);
  options.limits.max_scene_image_bytes = 8192;
  EXPECT_TRUE(engine::load_gltf(p, options).ok());
}

TEST(GltfMaterials, TangentsAreLoaded) {
  json d = textured_doc();
  // textured_doc's positions (36 bytes) and uvs (24 bytes), then 3 tangents (48 bytes).
  std::vector<float> data = {0,
                             0,
                             0,
                             1,
                             0,
                             0,
                             0,
                             1,
                             0,
                             /* uv */ 0,
                             0,
                             1,
                             0,
                             0,
                             1,
                             /* tangents */ 1,
                             0,
                             0,
                             1,
                             0,
                             2,
                             0,
                             1,
                             0,
                             0,
                             1,
                             -1};
  std::vector<std::uint8_t> bin(data.size() * 4);
  std::memcpy(bin.data(), data.data(), bin.size());
  d["buffers"][0] = {{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}};
  d["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 60}, {"byteLength", 48}});
  d["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
  d["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = 2;
  auto r = engine::load_gltf(write_doc(d));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  const std::vector<glm::vec4>& t = r->meshes[0].primitives[0].tangents;
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0], glm::vec4(1, 0, 0, 1));
  EXPECT_EQ(t[1], glm::vec4(0, 1, 0, 1));  // (0, 2, 0) normalised
  EXPECT_EQ(t[2], glm::vec4(0, 0, 1, -1));
}

}  // namespace
