// The generator is deterministic, the committed assets/ are what it writes today, the
// Draco twins load like their plain twins, and every scene has what its purpose needs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <engine/gltf.h>

#include "scenes.h"
#include "world_triangles.h"

namespace {

namespace fs = std::filesystem;
constexpr const char* kRegenerate =
    "regenerate with: cmake --build build --target gi-scenegen && build/tools/gi-scenegen/gi-scenegen --out assets";

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path generate(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("gi_scenegen_test_" + name);
  fs::remove_all(dir);
  const engine::Status st = scenegen::write_all_scenes(dir);
  EXPECT_TRUE(st) << st.error().to_string();
  return dir;
}

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(SceneGenerator, WritesIdenticalBytesEveryTime) {
  const fs::path a = generate("a"), b = generate("b");
  const auto names = files_in(a);
  ASSERT_EQ(names, files_in(b));
  ASSERT_GE(names.size(), 8u);
  for (const std::string& n : names) EXPECT_EQ(read_bytes(a / n), read_bytes(b / n)) << n;
}

TEST(SceneGenerator, CommittedAssetsAreUpToDate) {
  const fs::path fresh = generate("fresh");
  const fs::path committed = fs::path(GI_SOURCE_DIR) / "assets";
  for (const std::string& n : files_in(fresh)) {
    ASSERT_TRUE(fs::exists(committed / n)) << "assets/" << n << " is missing; " << kRegenerate;
    EXPECT_TRUE(read_bytes(committed / n) == read_bytes(fresh / n)) << "assets/" << n << " is stale; " << kRegenerate;
  }
}

// Largest extent of the positions divided by the number of quantization steps.
float quantization_step(const std::vector<glm::vec3>& positions, int bits) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 e = hi - lo;
  return std::max({e.x, e.y, e.z}) / static_cast<float>((1 << bits) - 1);
}

void expect_draco_twin(const std::string& plain_name, const std::string& draco_name) {
  const fs::path dir = fs::path(GI_SOURCE_DIR) / "assets";
  auto plain = engine::load_gltf(dir / plain_name);
  auto draco = engine::load_gltf(dir / draco_name);
  ASSERT_TRUE(plain) << plain.error().to_string();
  ASSERT_TRUE(draco) << draco.error().to_string();
  ASSERT_EQ(plain->meshes.size(), draco->meshes.size());
  ASSERT_EQ(plain->nodes.size(), draco->nodes.size());
  ASSERT_EQ(plain->lights.size(), draco->lights.size());
  const int bits = engine::GltfWriteOptions{}.draco_position_bits;
  for (std::size_t m = 0; m < plain->meshes.size(); ++m) {
    ASSERT_EQ(plain->meshes[m].primitives.size(), draco->meshes[m].primitives.size());
    for (std::size_t k = 0; k < plain->meshes[m].primitives.size(); ++k) {
      const engine::Primitive& a = plain->meshes[m].primitives[k];
      const engine::Primitive& b = draco->meshes[m].primitives[k];
      EXPECT_EQ(a.indices.size(), b.indices.size()) << "triangle count, mesh " << plain->meshes[m].name;
      EXPECT_EQ(a.material, b.material);
      EXPECT_EQ(b.normals.size(), b.positions.size());
      EXPECT_EQ(b.uv0.size(), b.positions.size());
      // Every decoded vertex lies within one quantization step of an original one, and
      // every original vertex has a decoded one within a step.
      const float step = quantization_step(a.positions, bits);
      auto nearest = [](glm::vec3 p, const std::vector<glm::vec3>& set) {
        float d = 1e30f;
        for (const glm::vec3& q : set) d = std::min(d, glm::length(p - q));
        return d;
      };
      for (const glm::vec3& p : b.positions) EXPECT_LE(nearest(p, a.positions), step) << plain->meshes[m].name;
      for (const glm::vec3& p : a.positions) EXPECT_LE(nearest(p, b.positions), step) << plain->meshes[m].name;
    }
  }
}

TEST(SceneGenerator, DracoTwinsLoadLikeTheirPlainTwins) {
  expect_draco_twin("crates_room.gltf", "crates_room.draco.glb");
  expect_draco_twin("demo_level.gltf", "demo_level.draco.glb");
}

TEST(SceneGenerator, EverySceneHasACameraNormalsAndUvs) {
  for (const scenegen::GeneratedScene& s : scenegen::all_scenes()) {
    const int cam = scenegen_test::find_node(s.asset, "camera");
    ASSERT_GE(cam, 0) << s.file_name;
    EXPECT_GE(s.asset.nodes[static_cast<std::size_t>(cam)].camera, 0) << s.file_name;
    std::size_t triangles = 0;
    for (const engine::Mesh& m : s.asset.meshes)
      for (const engine::Primitive& p : m.primitives) {
        EXPECT_EQ(p.normals.size(), p.positions.size()) << s.file_name << " " << m.name;
        EXPECT_EQ(p.uv0.size(), p.positions.size()) << s.file_name << " " << m.name;
        EXPECT_TRUE(p.uv1.empty()) << "TEXCOORD_1 is made by the light-atlas milestone";
        for (const glm::vec3& n : p.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
        triangles += p.indices.size() / 3;
      }
    EXPECT_LT(triangles, 20000u) << s.file_name;
    EXPECT_FALSE(s.asset.lights.empty()) << s.file_name;
  }
}

const engine::Node& node(const engine::SceneAsset& s, const std::string& name) {
  const int i = scenegen_test::find_node(s, name);
  GI_EXPECTS(i >= 0, "test asks for a node the scene has");
  return s.nodes[static_cast<std::size_t>(i)];
}

TEST(SceneGenerator, ScenesCarryTheirGiFlags) {
  const engine::SceneAsset crates = scenegen::crates_room();
  int dynamic_crates = 0;
  for (const engine::Node& n : crates.nodes)
    if (n.name.rfind("crate", 0) == 0 && n.gi.mobility == engine::Mobility::Dynamic) ++dynamic_crates;
  EXPECT_GE(dynamic_crates, 4);
  const engine::Node& red = node(crates, "crate_red");
  const engine::Material& red_mat = crates.materials[static_cast<std::size_t>(
      crates.meshes[static_cast<std::size_t>(red.mesh)].primitives[0].material)];
  EXPECT_GT(red_mat.base_color.x, 5.0f * red_mat.base_color.y);
  EXPECT_EQ(node(crates, "statue").gi.mobility, engine::Mobility::Static);

  const engine::SceneAsset glossy = scenegen::glossy_room();
  const engine::Node& floor = node(glossy, "glossy_floor");
  const engine::Material& fm = glossy.materials[static_cast<std::size_t>(
      glossy.meshes[static_cast<std::size_t>(floor.mesh)].primitives[0].material)];
  EXPECT_FLOAT_EQ(fm.roughness, 0.15f);
  EXPECT_FLOAT_EQ(fm.metallic, 0.0f);

  const engine::SceneAsset spot = scenegen::spot_chamber();
  ASSERT_EQ(spot.lights.size(), 1u);
  EXPECT_EQ(spot.lights[0].light.type, engine::LightType::Spot);

  const engine::SceneAsset demo = scenegen::demo_level();
  const engine::Node& lamp = node(demo, "swinging_lamp");
  EXPECT_TRUE(demo.lights[static_cast<std::size_t>(lamp.light)].light.moves);
  EXPECT_GE(lamp.parent, 0) << "the lamp hangs from a pivot that the game swings";
  int static_lights = 0;
  for (const engine::NamedLight& l : demo.lights) static_lights += l.light.moves ? 0 : 1;
  EXPECT_GE(static_lights, 2);
  EXPECT_EQ(node(demo, "crate_red").gi.mobility, engine::Mobility::Dynamic);
}

}  // namespace
