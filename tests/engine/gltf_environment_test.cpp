// The glTF scene's "gi" extras (docs/scene-format.md): a sky and a sun, loaded into
// SceneAsset::environment (the sun as a directional light on a node of its own), written
// back by engine::write_gltf, and refused with a message naming what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include <engine/gltf.h>

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

fs::path dir() {
  const fs::path d = fs::path(GI_BINARY_DIR) / "test_output" / "gltf_environment";
  fs::create_directories(d);
  return d;
}

engine::SceneAsset ground() {
  engine::SceneAsset a;
  engine::Primitive p;
  p.positions = {{-1, 0, -1}, {1, 0, -1}, {0, 0, 1}};
  p.indices = {0, 2, 1};
  a.meshes.push_back({.name = "ground", .primitives = {p}});
  engine::Node n;
  n.name = "ground";
  n.mesh = 0;
  a.nodes.push_back(n);
  return a;
}

/// ground() written, with `gi` as its scene's extras.gi; returns the path.
fs::path with_scene_gi(const std::string& name, const json& gi) {
  const fs::path path = dir() / name;
  EXPECT_TRUE(engine::write_gltf(ground(), path));
  std::ifstream in(path);
  json doc = json::parse(in);
  doc["scenes"][0]["extras"]["gi"] = gi;
  std::ofstream(path) << doc.dump(1);
  return path;
}

}  // namespace

TEST(GltfEnvironment, SkyAndSunLoadTheSunAsADirectionalLightOnItsOwnNode) {
  const fs::path path = with_scene_gi(
      "sky_sun.gltf", json::parse(R"({"sky": {"radiance": [0.5, 0.6, 0.9]},
                                      "sun": {"direction": [0, -2, 0], "irradiance": [800, 700, 600],
                                              "angular_radius_deg": 0.5}})"));
  auto a = engine::load_gltf(path);
  ASSERT_TRUE(a) << a.error().to_string();
  EXPECT_EQ(a->environment.sky_radiance, glm::vec3(0.5f, 0.6f, 0.9f));
  ASSERT_EQ(a->environment.sun_node, 1);
  ASSERT_EQ(a->environment.sun_light, 0);
  EXPECT_NEAR(a->environment.sun_angular_radius_rad, 0.5 * 3.14159265 / 180.0, 1e-6);
  const engine::Node& sun = a->nodes[1];
  EXPECT_EQ(sun.parent, -1);
  EXPECT_EQ(sun.light, 0);
  const glm::vec3 shines = sun.rotation * glm::vec3(0, 0, -1);  // a directional light's -Z
  EXPECT_NEAR(shines.y, -1.0f, 1e-5f);
  const engine::Light& l = a->lights[0].light;
  EXPECT_EQ(l.type, engine::LightType::Directional);
  EXPECT_FLOAT_EQ(l.intensity, 800.0f);  // W/m^2, engine units as written
  EXPECT_NEAR(l.color.z, 600.0f / 800.0f, 1e-6f);
}

TEST(GltfEnvironment, WriterWritesSkyAndSunBackAsSceneExtras) {
  auto a = engine::load_gltf(with_scene_gi(
      "roundtrip_in.gltf", json::parse(R"({"sky": {"radiance": [1, 2, 3]},
                                           "sun": {"direction": [1, -1, 0], "irradiance": [5, 5, 5]}})")));
  ASSERT_TRUE(a) << a.error().to_string();
  const fs::path out = dir() / "roundtrip_out.glb";
  ASSERT_TRUE(engine::write_gltf(*a, out));
  auto b = engine::load_gltf(out);
  ASSERT_TRUE(b) << b.error().to_string();
  EXPECT_EQ(b->environment.sky_radiance, glm::vec3(1, 2, 3));
  EXPECT_EQ(b->nodes.size(), a->nodes.size());  // the sun's node is not written twice
  EXPECT_EQ(b->lights.size(), a->lights.size());
  ASSERT_EQ(b->environment.sun_node, a->environment.sun_node);
  EXPECT_NEAR(b->environment.sun_angular_radius_rad, a->environment.sun_angular_radius_rad, 1e-6f);
  const glm::vec3 da = a->nodes[1].rotation * glm::vec3(0, 0, -1), db = b->nodes[1].rotation * glm::vec3(0, 0, -1);
  EXPECT_NEAR(glm::length(da - db), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(da - glm::normalize(glm::vec3(1, -1, 0))), 0.0f, 1e-5f);
}

TEST(GltfEnvironment, NoExtrasNoEnvironment) {
  const fs::path path = dir() / "plain.gltf";
  ASSERT_TRUE(engine::write_gltf(ground(), path));
  auto a = engine::load_gltf(path);
  ASSERT_TRUE(a) << a.error().to_string();
  EXPECT_EQ(a->environment.sky_radiance, glm::vec3(0.0f));
  EXPECT_EQ(a->environment.sun_light, -1);
  EXPECT_EQ(a->nodes.size(), 1u);
  std::ifstream in(path);
  EXPECT_FALSE(json::parse(in)["scenes"][0].contains("extras"));
}

TEST(GltfEnvironment, MalformedSkyOrSunIsAnErrorNamingIt) {
  const struct {
    const char* gi;
    const char* expect;
  } cases[] = {
      {R"({"sky": {"radiance": [1, -1, 1]}})", "scene 0 extras.gi.sky"},
      {R"({"sky": {"radiance": [1, 1]}})", "radiance"},
      {R"({"sky": 3})", "scene 0 extras.gi.sky"},
      {R"({"sky": {}})", "needs 'radiance'"},
      {R"({"sun": {"direction": [0, 0, 0], "irradiance": [1, 1, 1]}})", "'direction' must not be zero"},
      {R"({"sun": {"direction": [0, -1, 0]}})", "needs 'direction' and 'irradiance'"},
      {R"({"sun": {"direction": [0, -1, 0], "irradiance": [1, 1, 1], "angular_radius_deg": 90}})",
       "angular_radius_deg"},
      {R"([1, 2])", "scene 0 extras.gi"},
  };
  int i = 0;
  for (const auto& c : cases) {
    auto a = engine::load_gltf(with_scene_gi("bad_" + std::to_string(i++) + ".gltf", json::parse(c.gi)));
    ASSERT_FALSE(a) << c.gi;
    EXPECT_NE(a.error().to_string().find(c.expect), std::string::npos) << c.gi << " -> " << a.error().to_string();
  }
}
