// engine::write_gltf: round trips through engine::load_gltf (.gltf and .glb), byte
// determinism, all-or-nothing output, Draco within quantization and bad-input errors.
#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("gi_gltf_writer_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

engine::Primitive grid_primitive(int n, float size, bool with_uv1, int material) {
  engine::Primitive p;
  p.material = material;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(n), v = static_cast<float>(j) / static_cast<float>(n);
      p.positions.emplace_back(size * u, 0.1f * std::sin(7.0f * u) * v, size * v - 0.3f);
      p.normals.push_back(glm::normalize(glm::vec3(0.1f * u, 1.0f, -0.2f * v)));
      p.uv0.emplace_back(u * 2.0f, v);
      if (with_uv1) p.uv1.emplace_back(0.25f + 0.5f * u, 0.5f * v);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (n + 1) + i);
      const auto b = a + 1, c = a + static_cast<std::uint32_t>(n + 1), d = c + 1;
      p.indices.insert(p.indices.end(), {a, c, b, b, c, d});
    }
  return p;
}

// A scene using every feature the writer supports.
engine::SceneAsset feature_scene() {
  engine::SceneAsset s;
  engine::Material plain;
  plain.name = "plain";
  plain.base_color = {0.7f, 0.5f, 0.3f, 1.0f};
  plain.roughness = 0.15f;
  plain.double_sided = true;
  plain.base_color_texture.image = 0;
  plain.specular_factor = 0.25f;                     // KHR_materials_specular
  plain.specular_color_factor = {2.0f, 1.0f, 0.5f};  // above 1 is allowed (the BRDF clamps F0)
  engine::Material glow;
  glow.name = "glow";
  glow.metallic = 1.0f;
  glow.roughness = 0.4f;
  glow.emissive = {18.387f, 10.987f, 2.754f};  // above 1: KHR_materials_emissive_strength
  engine::Material dim;
  dim.name = "dim";
  dim.emissive = {0.5f, 0.25f, 0.0f};
  // Issue 33: a cut-out leaf with a clamped, nearest-filtered base colour on TEXCOORD_1 under
  // a KHR_texture_transform, a scaled normal map sharing the image but not the sampler, and
  // a blended pane reusing the first sampler (one sampler per distinct TextureSampler).
  engine::Material leaf;
  leaf.name = "leaf";
  leaf.base_color_texture = {.image = 1, .texcoord = 1};
  leaf.base_color_texture.sampler = {.wrap_s = engine::TextureWrap::ClampToEdge,
                                     .wrap_t = engine::TextureWrap::MirroredRepeat,
                                     .mag_linear = false,
                                     .min_linear = false,
                                     .mipmaps = false};
  leaf.base_color_texture.transform = {.offset = {0.25f, -0.5f}, .rotation_rad = 0.3f, .scale = {2.0f, 0.5f}};
  leaf.normal_texture = {.image = 1};
  leaf.normal_scale = 0.5f;
  leaf.alpha_mode = engine::AlphaMode::Mask;
  leaf.alpha_cutoff = 0.3f;
  leaf.double_sided = true;
  engine::Material pane;
  pane.name = "pane";
  pane.base_color = {0.9f, 0.95f, 1.0f, 0.4f};
  pane.alpha_mode = engine::AlphaMode::Blend;
  pane.emissive_texture = leaf.base_color_texture;
  pane.emissive_texture.transform = {};
  pane.emissive = {0.1f, 0.1f, 0.1f};
  s.materials = {plain, glow, dim, leaf, pane};

  engine::Image img;
  img.name = "checker";
  img.width = 4;
  img.height = 2;
  for (int i = 0; i < img.width * img.height; ++i)
    img.rgba8.insert(img.rgba8.end(),
                     {static_cast<std::uint8_t>(30 * i), static_cast<std::uint8_t>(255 - 20 * i), 7, 255});
  s.images.push_back(img);
  engine::Image mask;  // alpha 0 or 255 in a 2x2 checker
  mask.name = "mask";
  mask.width = 2;
  mask.height = 2;
  mask.rgba8 = {40, 160, 30, 255, 40, 160, 30, 0, 40, 160, 30, 0, 40, 160, 30, 255};
  s.images.push_back(mask);

  engine::Mesh m;
  m.name = "ground";
  m.primitives.push_back(grid_primitive(8, 2.0f, true, 0));
  m.primitives.push_back(grid_primitive(3, 1.0f, false, 1));
  s.meshes.push_back(m);
  engine::Mesh big;  // more than 65535 vertices: 32-bit indices
  big.name = "big";
  big.primitives.push_back(grid_primitive(260, 5.0f, false, 2));
  s.meshes.push_back(big);

  engine::Light point{
      .type = engine::LightType::Point, .color = {1.0f, 0.9f, 0.8f}, .intensity = 12.0f, .range_m = 20.0f};
  engine::Light spot{.type = engine::LightType::Spot, .intensity = 3.0f};
  spot.inner_cone_rad = glm::radians(30.0f);
  spot.outer_cone_rad = glm::radians(40.0f);
  spot.moves = true;
  engine::Light sun{.type = engine::LightType::Directional, .color = {1.0f, 1.0f, 0.95f}, .intensity = 4.5f};
  engine::Light area{.type = engine::LightType::Area, .color = {2.0f, 1.0f, 0.5f}, .intensity = 10.0f};
  area.area_size_m = {0.13f, 0.105f};
  s.lights = {{"point", point}, {"spot", spot}, {"sun", sun}, {"panel", area}};
  engine::Camera cam{.yfov_rad = glm::radians(39.3077f), .znear_m = 0.02f, .zfar_m = 80.0f, .aspect = 1.5f};
  s.cameras = {{"cam", cam}};

  auto node = [&](std::string name, int parent) -> engine::Node& {
    engine::Node n;
    n.name = std::move(name);
    n.parent = parent;
    s.nodes.push_back(n);
    return s.nodes.back();
  };
  node("ground", -1).mesh = 0;
  s.nodes.back().gi.mobility = engine::Mobility::Static;
  s.nodes.back().translation = {1.0f, -0.5f, 2.0f};
  node("pivot", -1).gi.mobility = engine::Mobility::Dynamic;
  s.nodes.back().rotation = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 2, 3)));
  s.nodes.back().scale = {2.0f, 2.0f, 2.0f};
  node("big", 1).mesh = 1;
  node("point_node", 0).light = 0;
  node("spot_node", 1).light = 1;
  s.nodes.back().rotation = glm::angleAxis(glm::radians(-90.0f), glm::vec3(1, 0, 0));
  node("sun_node", -1).light = 2;
  node("panel_node", -1).light = 3;
  s.nodes.back().translation = {0.0f, 3.0f, 0.0f};
  node("camera", -1).camera = 0;
  s.nodes.back().translation = {0.0f, 1.7f, 5.0f};
  return s;
}

const engine::Node* find_node(const engine::SceneAsset& s, const std::string& name) {
  for (const engine::Node& n : s.nodes)
    if (n.name == name) return &n;
  return nullptr;
}

void expect_vec_near(glm::vec3 a, glm::vec3 b, float tol, const std::string& what) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tol) << what << " component " << i;
}

// Everything written must come back: exact for geometry (floats are stored raw), 1e-6
// relative for values written as JSON decimals and converted between units.
void expect_round_trip(const engine::SceneAsset& in, const engine::SceneAsset& out) {
  ASSERT_EQ(out.meshes.size(), in.meshes.size());
  for (std::size_t m = 0; m < in.meshes.size(); ++m) {
    ASSERT_EQ(out.meshes[m].primitives.size(), in.meshes[m].primitives.size());
    EXPECT_EQ(out.meshes[m].name, in.meshes[m].name);
    for (std::size_t k = 0; k < in.meshes[m].primitives.size(); ++k) {
      const engine::Primitive& a = in.meshes[m].primitives[k];
      const engine::Primitive& b = out.meshes[m].primitives[k];
      EXPECT_EQ(b.positions, a.positions);
      // The loader may renormalize normals: equal within float rounding.
      ASSERT_EQ(b.normals.size(), a.normals.size());
      for (std::size_t i = 0; i < a.normals.size(); ++i) expect_vec_near(b.normals[i], a.normals[i], 1e-6f, "normal");
      EXPECT_EQ(b.uv0, a.uv0);
      EXPECT_EQ(b.uv1, a.uv1);
      EXPECT_EQ(b.indices, a.indices);
      EXPECT_EQ(b.material, a.material);
    }
  }
  ASSERT_EQ(out.materials.size(), in.materials.size());
  for (std::size_t i = 0; i < in.materials.size(); ++i) {
    const engine::Material& a = in.materials[i];
    const engine::Material& b = out.materials[i];
    EXPECT_EQ(b.name, a.name);
    for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(b.base_color[c], a.base_color[c]);
    EXPECT_FLOAT_EQ(b.metallic, a.metallic);
    EXPECT_FLOAT_EQ(b.roughness, a.roughness);
    expect_vec_near(b.emissive, a.emissive, 1e-5f * (1.0f + a.emissive.x), a.name + " emissive");
    EXPECT_EQ(b.double_sided, a.double_sided);
    for (const auto& [ta, tb] :
         {std::pair{&a.base_color_texture, &b.base_color_texture},
          std::pair{&a.metallic_roughness_texture, &b.metallic_roughness_texture},
          std::pair{&a.normal_texture, &b.normal_texture}, std::pair{&a.emissive_texture, &b.emissive_texture}}) {
      EXPECT_EQ(tb->image, ta->image) << a.name;
      EXPECT_EQ(tb->texcoord, ta->texcoord) << a.name;
    }
    EXPECT_FLOAT_EQ(b.specular_factor, a.specular_factor) << a.name;
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(b.specular_color_factor[c], a.specular_color_factor[c]) << a.name;
  }
  ASSERT_EQ(out.images.size(), in.images.size());
  for (std::size_t i = 0; i < in.images.size(); ++i) {
    EXPECT_EQ(out.images[i].width, in.images[i].width);
    EXPECT_EQ(out.images[i].height, in.images[i].height);
    EXPECT_EQ(out.images[i].rgba8, in.images[i].rgba8);
  }
  ASSERT_EQ(out.nodes.size(), in.nodes.size());
  for (const engine::Node& a : in.nodes) {
    const engine::Node* b = find_node(out, a.name);
    ASSERT_NE(b, nullptr) << a.name;
    EXPECT_EQ(b->translation, a.translation) << a.name;
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(b->rotation[c], a.rotation[c], 1e-7f) << a.name;
    EXPECT_EQ(b->scale, a.scale) << a.name;
    EXPECT_EQ(b->mesh, a.mesh) << a.name;
    EXPECT_EQ(b->gi.mobility, a.gi.mobility) << a.name;
    const std::string parent_in = a.parent >= 0 ? in.nodes[static_cast<std::size_t>(a.parent)].name : "";
    const std::string parent_out = b->parent >= 0 ? out.nodes[static_cast<std::size_t>(b->parent)].name : "";
    EXPECT_EQ(parent_out, parent_in) << a.name;
    ASSERT_EQ(b->camera >= 0, a.camera >= 0) << a.name;
    if (a.camera >= 0) {
      const engine::Camera& ca = in.cameras[static_cast<std::size_t>(a.camera)].camera;
      const engine::Camera& cb = out.cameras[static_cast<std::size_t>(b->camera)].camera;
      EXPECT_FLOAT_EQ(cb.yfov_rad, ca.yfov_rad);
      EXPECT_FLOAT_EQ(cb.znear_m, ca.znear_m);
      EXPECT_FLOAT_EQ(cb.zfar_m, ca.zfar_m);
      EXPECT_FLOAT_EQ(cb.aspect, ca.aspect);
    }
    ASSERT_EQ(b->light >= 0, a.light >= 0) << a.name;
    if (a.light >= 0) {
      const engine::Light& la = in.lights[static_cast<std::size_t>(a.light)].light;
      const engine::Light& lb = out.lights[static_cast<std::size_t>(b->light)].light;
      EXPECT_EQ(lb.type, la.type) << a.name;
      expect_vec_near(lb.color * lb.intensity, la.color * la.intensity, 1e-5f * la.intensity,
                      a.name + " color x intensity");
      EXPECT_EQ(lb.moves, la.moves) << a.name;
      if (la.type == engine::LightType::Spot) {
        EXPECT_NEAR(lb.inner_cone_rad, la.inner_cone_rad, 1e-6f);
        EXPECT_NEAR(lb.outer_cone_rad, la.outer_cone_rad, 1e-6f);
      }
      if (la.type == engine::LightType::Point) {
        EXPECT_FLOAT_EQ(lb.range_m, la.range_m);
      }
      if (la.type == engine::LightType::Area) {
        EXPECT_FLOAT_EQ(lb.area_size_m.x, la.area_size_m.x);
        EXPECT_FLOAT_EQ(lb.area_size_m.y, la.area_size_m.y);
      }
    }
  }
}

TEST(GltfWriter, RoundTripsEveryFeatureThroughGltfAndBin) {
  const engine::SceneAsset scene = feature_scene();
  const fs::path path = temp_dir("text") / "scene.gltf";
  const engine::Status st = engine::write_gltf(scene, path);
  ASSERT_TRUE(st) << st.error().to_string();
  EXPECT_TRUE(fs::exists(path.parent_path() / "scene.bin"));
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  expect_round_trip(scene, *loaded);
}

TEST(GltfWriter, RoundTripsEveryFeatureThroughGlb) {
  const engine::SceneAsset scene = feature_scene();
  const fs::path path = temp_dir("binary") / "scene.glb";
  const engine::Status st = engine::write_gltf(scene, path, {.binary = true});
  ASSERT_TRUE(st) << st.error().to_string();
  EXPECT_FALSE(fs::exists(path.parent_path() / "scene.bin"));
  EXPECT_EQ(read_bytes(path).substr(0, 4), "glTF");
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  expect_round_trip(scene, *loaded);
}

// Issue 33's material data beyond image and texCoord: samplers, KHR_texture_transform,
// alphaMode / alphaCutoff and normalTexture.scale.
void expect_texture_state_round_trip(const engine::SceneAsset& in, const engine::SceneAsset& out) {
  ASSERT_EQ(out.materials.size(), in.materials.size());
  for (std::size_t i = 0; i < in.materials.size(); ++i) {
    const engine::Material& a = in.materials[i];
    const engine::Material& b = out.materials[i];
    EXPECT_EQ(b.alpha_mode, a.alpha_mode) << a.name;
    EXPECT_FLOAT_EQ(b.alpha_cutoff, a.alpha_cutoff) << a.name;
    EXPECT_FLOAT_EQ(b.normal_scale, a.normal_scale) << a.name;
    for (const auto& [ta, tb] :
         {std::pair{&a.base_color_texture, &b.base_color_texture},
          std::pair{&a.metallic_roughness_texture, &b.metallic_roughness_texture},
          std::pair{&a.normal_texture, &b.normal_texture}, std::pair{&a.emissive_texture, &b.emissive_texture}}) {
      if (!ta->present()) continue;
      EXPECT_EQ(tb->sampler.wrap_s, ta->sampler.wrap_s) << a.name;
      EXPECT_EQ(tb->sampler.wrap_t, ta->sampler.wrap_t) << a.name;
      EXPECT_EQ(tb->sampler.mag_linear, ta->sampler.mag_linear) << a.name;
      EXPECT_EQ(tb->sampler.min_linear, ta->sampler.min_linear) << a.name;
      EXPECT_EQ(tb->sampler.mipmaps, ta->sampler.mipmaps) << a.name;
      EXPECT_FLOAT_EQ(tb->transform.offset.x, ta->transform.offset.x) << a.name;
      EXPECT_FLOAT_EQ(tb->transform.offset.y, ta->transform.offset.y) << a.name;
      EXPECT_FLOAT_EQ(tb->transform.rotation_rad, ta->transform.rotation_rad) << a.name;
      EXPECT_FLOAT_EQ(tb->transform.scale.x, ta->transform.scale.x) << a.name;
      EXPECT_FLOAT_EQ(tb->transform.scale.y, ta->transform.scale.y) << a.name;
    }
  }
}

// What the writer writes, the loader reads back: samplers, KHR_texture_transform, alpha.
TEST(GltfWriter, RoundTripsSamplersTransformsAndAlpha) {
  const engine::SceneAsset scene = feature_scene();
  for (const char* name : {"scene.gltf", "scene.glb"}) {
    const fs::path path = temp_dir("texture_state") / name;
    const engine::Status st = engine::write_gltf(scene, path);
    ASSERT_TRUE(st) << st.error().to_string();
    auto loaded = engine::load_gltf(path);
    ASSERT_TRUE(loaded) << loaded.error().to_string();
    expect_texture_state_round_trip(scene, *loaded);
  }
}

TEST(GltfWriter, WritesSamplersTransformsAndAlphaAsGltfDefines) {
  const fs::path path = temp_dir("texture_json") / "scene.gltf";
  ASSERT_TRUE(engine::write_gltf(feature_scene(), path));
  const nlohmann::json doc = nlohmann::json::parse(read_bytes(path));
  // Two distinct samplers (the default and the leaf's), three (image, sampler) textures.
  const nlohmann::json samplers = nlohmann::json::parse(R"([
    {"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497},
    {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33648}])");
  EXPECT_EQ(doc.at("samplers"), samplers);
  const nlohmann::json textures = nlohmann::json::parse(R"([
    {"sampler": 0, "source": 0}, {"sampler": 1, "source": 1}, {"sampler": 0, "source": 1}])");
  EXPECT_EQ(doc.at("textures"), textures);
  const nlohmann::json& mats = doc.at("materials");
  ASSERT_EQ(mats.size(), 5u);
  // plain: defaults are left out (no alphaMode, no texCoord, no transform).
  EXPECT_FALSE(mats[0].contains("alphaMode"));
  EXPECT_FALSE(mats[0].contains("alphaCutoff"));
  EXPECT_EQ(mats[0].at("pbrMetallicRoughness").at("baseColorTexture"), nlohmann::json({{"index", 0}}));
  // leaf: MASK with its cutoff, TEXCOORD_1 and the transform, normal scale.
  const nlohmann::json& leaf = mats[3];
  EXPECT_EQ(leaf.at("alphaMode"), "MASK");
  EXPECT_DOUBLE_EQ(leaf.at("alphaCutoff").get<double>(), 0.3);
  const nlohmann::json& base = leaf.at("pbrMetallicRoughness").at("baseColorTexture");
  EXPECT_EQ(base.at("index"), 1);
  EXPECT_EQ(base.at("texCoord"), 1);
  const nlohmann::json transform =
      nlohmann::json::parse(R"({"offset": [0.25, -0.5], "rotation": 0.3, "scale": [2.0, 0.5]})");
  EXPECT_EQ(base.at("extensions").at("KHR_texture_transform"), transform);
  EXPECT_EQ(leaf.at("normalTexture"), nlohmann::json::parse(R"({"index": 2, "scale": 0.5})"));
  // pane: BLEND without a cutoff (glTF ignores it outside MASK); its emissive texture has
  // the leaf's sampler and no transform.
  EXPECT_EQ(mats[4].at("alphaMode"), "BLEND");
  EXPECT_FALSE(mats[4].contains("alphaCutoff"));
  EXPECT_EQ(mats[4].at("emissiveTexture"), nlohmann::json::parse(R"({"index": 1, "texCoord": 1})"));
  const auto used = doc.at("extensionsUsed").get<std::vector<std::string>>();
  EXPECT_NE(std::find(used.begin(), used.end(), "KHR_texture_transform"), used.end());
  EXPECT_FALSE(doc.contains("extensionsRequired")) << "a viewer without the transform still draws the texture";
}

TEST(GltfWriter, RefusesATextureOfAMissingImage) {
  engine::SceneAsset scene = feature_scene();
  scene.materials[3].normal_texture.image = 7;
  const fs::path path = temp_dir("missing_image") / "scene.gltf";
  const engine::Status st = engine::write_gltf(scene, path);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.error().location, "materials[3] normalTexture");
  EXPECT_NE(st.error().message.find("image 7 is out of range"), std::string::npos) << st.error().to_string();
  EXPECT_FALSE(fs::exists(path));
}

TEST(GltfWriter, MeshWithoutPrimitivesIsLeftOutAndItsNodesKeepNoMesh) {
  // Found by fuzz_gltf (tests/fuzz/regressions/gltf/): the loader keeps a mesh of only points
  // or lines (or an unused undecodable one) with no primitives; the writer refused the scene.
  engine::SceneAsset scene = feature_scene();
  const std::size_t meshes = scene.meshes.size();
  ASSERT_GE(meshes, 1u);
  scene.meshes.insert(scene.meshes.begin(), engine::Mesh{.name = "lines_only"});
  for (engine::Node& n : scene.nodes)
    if (n.mesh >= 0) ++n.mesh;
  scene.nodes.push_back(engine::Node{.name = "wire", .mesh = 0});
  const fs::path path = temp_dir("empty_mesh") / "scene.glb";
  const engine::Status st = engine::write_gltf(scene, path, {.binary = true});
  ASSERT_TRUE(st) << st.error().to_string();
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  EXPECT_EQ(loaded->meshes.size(), meshes);
  ASSERT_EQ(loaded->nodes.size(), scene.nodes.size());
  for (const engine::Node& n : loaded->nodes) {
    if (n.name == "wire") {
      EXPECT_EQ(n.mesh, -1);
    }
  }
  // The other nodes still name their meshes, shifted back by the one left out.
  for (std::size_t i = 0; i + 1 < scene.nodes.size(); ++i) {
    const engine::Node& before = scene.nodes[i];
    const auto it = std::find_if(loaded->nodes.begin(), loaded->nodes.end(),
                                 [&](const engine::Node& n) { return n.name == before.name; });
    ASSERT_NE(it, loaded->nodes.end()) << before.name;
    EXPECT_EQ(it->mesh, before.mesh >= 0 ? before.mesh - 1 : -1) << before.name;
  }
}

TEST(GltfWriter, AnImageWithNothingToWriteIsLeftOutAndTheTexturesKeepTheirPixels) {
  // Found by fuzz_gltf (tests/fuzz/regressions/gltf/): an embedded image that does not decode
  // and no material uses loads with neither pixels nor a URI; the writer refused the scene.
  engine::SceneAsset scene = feature_scene();
  ASSERT_FALSE(scene.images.empty());
  scene.images.insert(scene.images.begin(), engine::Image{.name = "undecodable"});
  for (engine::Material& m : scene.materials)
    for (engine::TextureRef* t :
         {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.emissive_texture})
      if (t->present()) ++t->image;
  const fs::path path = temp_dir("empty_image") / "scene.glb";
  const engine::Status st = engine::write_gltf(scene, path, {.binary = true});
  ASSERT_TRUE(st) << st.error().to_string();
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  EXPECT_EQ(loaded->images.size(), scene.images.size() - 1);
  ASSERT_EQ(loaded->materials.size(), scene.materials.size());
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const engine::TextureRef& before = scene.materials[i].base_color_texture;
    const engine::TextureRef& after = loaded->materials[i].base_color_texture;
    ASSERT_EQ(after.present(), before.present()) << i;
    if (before.present()) {
      EXPECT_EQ(loaded->images[static_cast<std::size_t>(after.image)].rgba8,
                scene.images[static_cast<std::size_t>(before.image)].rgba8)
          << "materials[" << i << "] reads another image's pixels";
    }
  }
  // A material that uses such an image is refused, naming the image.
  scene.materials[0].base_color_texture.image = 0;
  const fs::path refused = temp_dir("empty_image_used") / "scene.glb";
  const engine::Status used = engine::write_gltf(scene, refused, {.binary = true});
  ASSERT_FALSE(used);
  EXPECT_NE(used.error().message.find("image 0 has neither pixels nor a URI"), std::string::npos)
      << used.error().to_string();
  EXPECT_FALSE(fs::exists(refused));
}

TEST(GltfWriter, ABareNodeIsWrittenAsAnEmptyObject) {
  // Found by fuzz_gltf: a node with no name, an identity transform and nothing attached was
  // written as null, and the loader refused the file ("nodes 0: must be an object").
  engine::SceneAsset scene = feature_scene();
  scene.nodes.push_back(engine::Node{});
  const fs::path path = temp_dir("bare_node") / "scene.gltf";
  const engine::Status st = engine::write_gltf(scene, path);
  ASSERT_TRUE(st) << st.error().to_string();
  EXPECT_EQ(read_bytes(path).find("null"), std::string::npos);
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  EXPECT_EQ(loaded->nodes.size(), scene.nodes.size());
}

TEST(GltfWriter, RefusesANonFiniteNormalOrTextureCoordinate) {
  // The loader refuses such a file, so the writer must not write one (it checked positions only).
  const auto refused = [](engine::SceneAsset scene, const char* what) {
    const fs::path path = temp_dir("non_finite") / "scene.glb";
    fs::remove(path);
    const engine::Status st = engine::write_gltf(scene, path, {.binary = true});
    ASSERT_FALSE(st) << what;
    EXPECT_NE(st.error().to_string().find(what), std::string::npos) << st.error().to_string();
    EXPECT_FALSE(fs::exists(path)) << "nothing half-written";
  };
  const engine::SceneAsset scene = feature_scene();
  const auto has_both = [](const engine::Mesh& m) {
    return !m.primitives.empty() && !m.primitives[0].normals.empty() && !m.primitives[0].uv0.empty();
  };
  const auto it = std::find_if(scene.meshes.begin(), scene.meshes.end(), has_both);
  ASSERT_NE(it, scene.meshes.end());
  const auto mesh = static_cast<std::size_t>(it - scene.meshes.begin());
  engine::SceneAsset bad_normal = scene;
  bad_normal.meshes[mesh].primitives[0].normals[0].y = std::numeric_limits<float>::quiet_NaN();
  refused(bad_normal, "normal is NaN or infinite");
  engine::SceneAsset bad_uv = scene;
  bad_uv.meshes[mesh].primitives[0].uv0[0].x = std::numeric_limits<float>::infinity();
  refused(bad_uv, "texture coordinate is NaN or infinite");
}

TEST(GltfWriter, WritesPhotometricUnitsAndEmissiveStrength) {
  const fs::path path = temp_dir("units") / "scene.gltf";
  ASSERT_TRUE(engine::write_gltf(feature_scene(), path));
  const std::string json = read_bytes(path);
  // 12 W/sr x 683 lm/W = 8196 cd; 4.5 W/m^2 x 683 = 3073.5 lx.
  EXPECT_NE(json.find("8196"), std::string::npos);
  EXPECT_NE(json.find("3073.5"), std::string::npos);
  EXPECT_NE(json.find("\"emissiveStrength\": 18.387"), std::string::npos);
  EXPECT_NE(json.find("\"light_moves\": true"), std::string::npos);
  EXPECT_NE(json.find("\"size_m\""), std::string::npos);
  EXPECT_EQ(json.find("KHR_draco_mesh_compression"), std::string::npos);
}

TEST(GltfWriter, SameSceneGivesIdenticalBytes) {
  const engine::SceneAsset scene = feature_scene();
  const fs::path dir = temp_dir("determinism");
  for (const bool draco : {false, true}) {
    ASSERT_TRUE(engine::write_gltf(scene, dir / "a.glb", {.binary = true, .draco = draco}));
    ASSERT_TRUE(engine::write_gltf(scene, dir / "b.glb", {.binary = true, .draco = draco}));
    EXPECT_EQ(read_bytes(dir / "a.glb"), read_bytes(dir / "b.glb")) << "draco " << draco;
  }
  ASSERT_TRUE(engine::write_gltf(scene, dir / "c.gltf"));
  const std::string json1 = read_bytes(dir / "c.gltf"), bin1 = read_bytes(dir / "c.bin");
  ASSERT_TRUE(engine::write_gltf(scene, dir / "c.gltf"));
  EXPECT_EQ(read_bytes(dir / "c.gltf"), json1);
  EXPECT_EQ(read_bytes(dir / "c.bin"), bin1);
}

TEST(GltfWriter, FailedWriteReturnsErrorAndLeavesNoFile) {
  const fs::path dir = temp_dir("failure");
  // The folder does not exist: nothing can be written.
  const fs::path missing = dir / "no_such_folder" / "scene.gltf";
  const engine::Status st = engine::write_gltf(feature_scene(), missing);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().to_string().find("no_such_folder"), std::string::npos) << st.error().to_string();
  // The target name is taken by a folder: the .bin and the temporary files are written,
  // the final rename fails, and everything written is removed again.
  fs::create_directories(dir / "blocked.gltf" / "inside");
  const engine::Status st2 = engine::write_gltf(feature_scene(), dir / "blocked.gltf");
  ASSERT_FALSE(st2);
  EXPECT_NE(st2.error().file.find("blocked.gltf"), std::string::npos) << st2.error().to_string();
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"blocked.gltf"});
}

TEST(GltfWriter, RejectsInconsistentPrimitiveWithItsLocation) {
  engine::SceneAsset scene = feature_scene();
  scene.meshes[0].primitives[1].indices[4] = 1000;
  const fs::path path = temp_dir("bad") / "scene.gltf";
  const engine::Status st = engine::write_gltf(scene, path);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.error().location, "meshes[0].primitives[1]");
  EXPECT_NE(st.error().message.find("out of range"), std::string::npos);
  EXPECT_FALSE(fs::exists(path));
  scene = feature_scene();
  scene.meshes[0].primitives[0].normals.pop_back();
  EXPECT_FALSE(engine::write_gltf(scene, path));
  EXPECT_FALSE(fs::exists(path));
}

// Quantization step of `bits` over the largest extent of the primitive's bounding box.
float quantization_step(const std::vector<glm::vec3>& positions, int bits) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 ext = hi - lo;
  return std::max({ext.x, ext.y, ext.z}) / static_cast<float>((1 << bits) - 1);
}

TEST(GltfWriter, DracoPrimitivesMatchTheirPlainTwinsWithinQuantization) {
  const engine::SceneAsset scene = feature_scene();
  const fs::path path = temp_dir("draco") / "scene.glb";
  engine::GltfWriteOptions options{.binary = true, .draco = true};
  options.draco_position_bits = 11;
  ASSERT_TRUE(engine::write_gltf(scene, path, options));
  EXPECT_NE(read_bytes(path).find("\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]"), std::string::npos);
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  ASSERT_EQ(loaded->meshes.size(), scene.meshes.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    for (std::size_t k = 0; k < scene.meshes[m].primitives.size(); ++k) {
      const engine::Primitive& a = scene.meshes[m].primitives[k];
      const engine::Primitive& b = loaded->meshes[m].primitives[k];
      ASSERT_EQ(b.indices.size(), a.indices.size()) << "triangle count of mesh " << m;
      EXPECT_EQ(b.uv1.empty(), a.uv1.empty());
      EXPECT_EQ(b.material, a.material);
      // Draco may reorder vertices: compare each decoded triangle with the original
      // triangle whose centroid is nearest (grids give unique centroids).
      const float step = quantization_step(a.positions, options.draco_position_bits);
      if (a.positions.size() > 2000) continue;  // the big grid is checked by count only (O(n^2) match)
      for (std::size_t t = 0; t < b.indices.size(); t += 3) {
        const glm::vec3 cb =
            (b.positions[b.indices[t]] + b.positions[b.indices[t + 1]] + b.positions[b.indices[t + 2]]) / 3.0f;
        std::size_t best = 0;
        float best_d = 1e30f;
        for (std::size_t s = 0; s < a.indices.size(); s += 3) {
          const glm::vec3 ca =
              (a.positions[a.indices[s]] + a.positions[a.indices[s + 1]] + a.positions[a.indices[s + 2]]) / 3.0f;
          const float d = glm::length(ca - cb);
          if (d < best_d) {
            best_d = d;
            best = s;
          }
        }
        for (int c = 0; c < 3; ++c) {
          const glm::vec3 pb = b.positions[b.indices[t + static_cast<std::size_t>(c)]];
          float nearest = 1e30f;
          for (int e = 0; e < 3; ++e)
            nearest = std::min(nearest, glm::length(pb - a.positions[a.indices[best + static_cast<std::size_t>(e)]]));
          // Per component error <= step / 2, so the 3-D error <= step * sqrt(3) / 2 < step.
          EXPECT_LE(nearest, step) << "mesh " << m << " primitive " << k << " triangle " << t / 3;
        }
      }
    }
  }
}

}  // namespace
