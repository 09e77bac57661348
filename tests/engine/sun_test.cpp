// engine::set_sun (engine/sun.h): the sun a tool or a test gives a scene in memory is the
// very light and node the glTF loader makes from the scene's gi.sun, and a second sun
// replaces the first.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/sun.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

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

glm::vec3 shines(const engine::Node& n) { return n.rotation * glm::vec3(0.0f, 0.0f, -1.0f); }

}  // namespace

TEST(Sun, SetSunMakesTheLightAndNodeTheLoaderMakesFromGiSun) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "sun";
  fs::create_directories(dir);
  const fs::path path = dir / "sun.gltf";
  ASSERT_TRUE(engine::write_gltf(ground(), path));
  nlohmann::json doc;
  std::ifstream(path) >> doc;
  doc["scenes"][0]["extras"]["gi"]["sun"] = {
      {"direction", {0.3, -1.0, 0.2}}, {"irradiance", {700, 650, 600}}, {"angular_radius_deg", 0.5}};
  std::ofstream(path) << doc.dump(1);
  auto loaded = engine::load_gltf(path);
  ASSERT_TRUE(loaded) << loaded.error().to_string();

  engine::SceneAsset made = ground();
  engine::set_sun(made, {.direction = {0.3f, -1.0f, 0.2f},
                         .irradiance = {700.0f, 650.0f, 600.0f},
                         .angular_radius_rad = 0.5f * std::numbers::pi_v<float> / 180.0f});
  ASSERT_EQ(made.lights.size(), loaded->lights.size());
  ASSERT_EQ(made.nodes.size(), loaded->nodes.size());
  EXPECT_EQ(made.environment.sun_light, loaded->environment.sun_light);
  EXPECT_EQ(made.environment.sun_node, loaded->environment.sun_node);
  EXPECT_FLOAT_EQ(made.environment.sun_angular_radius_rad, loaded->environment.sun_angular_radius_rad);
  const engine::Light& a = made.lights[0].light;
  const engine::Light& b = loaded->lights[0].light;
  EXPECT_EQ(made.lights[0].name, "sun");
  EXPECT_EQ(a.type, engine::LightType::Directional);
  EXPECT_EQ(a.type, b.type);
  EXPECT_FLOAT_EQ(a.intensity, 700.0f);
  EXPECT_FLOAT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.color, b.color);
  EXPECT_FLOAT_EQ(a.angular_radius_rad, b.angular_radius_rad);
  const engine::Node& n = made.nodes[static_cast<std::size_t>(made.environment.sun_node)];
  EXPECT_EQ(n.parent, -1);
  EXPECT_EQ(n.name, "sun");
  EXPECT_NEAR(glm::length(shines(n) - glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f))), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(shines(n) - shines(loaded->nodes[1])), 0.0f, 1e-6f);
}

TEST(Sun, ASecondSunReplacesTheFirstInPlace) {
  engine::SceneAsset a = ground();
  engine::set_sun(a, {.direction = {0.0f, -1.0f, 0.0f}, .irradiance = glm::vec3(100.0f)});
  engine::Node camera;
  camera.name = "camera";
  a.nodes.push_back(camera);  // the sun's node need not stay last
  engine::set_sun(a, {.direction = {1.0f, -1.0f, 0.0f}, .irradiance = {0.0f, 0.0f, 0.0f}, .angular_radius_rad = 0.0f});
  ASSERT_EQ(a.lights.size(), 1u);
  ASSERT_EQ(a.nodes.size(), 3u);
  EXPECT_EQ(a.environment.sun_node, 1);
  EXPECT_EQ(a.nodes[1].light, 0);
  EXPECT_NEAR(glm::length(shines(a.nodes[1]) - glm::normalize(glm::vec3(1.0f, -1.0f, 0.0f))), 0.0f, 1e-6f);
  EXPECT_EQ(a.lights[0].light.intensity, 0.0f);
  EXPECT_EQ(a.lights[0].light.color, glm::vec3(1.0f)) << "a dark sun is white, not NaN";
  EXPECT_EQ(a.environment.sun_angular_radius_rad, 0.0f);
}

TEST(SunDeathTest, AZeroDirectionIsAProgrammerError) {
  engine::SceneAsset a = ground();
  EXPECT_DEATH(engine::set_sun(a, {.direction = glm::vec3(0.0f), .irradiance = glm::vec3(1.0f)}),
               "the sun's direction must be finite and not zero");
}
