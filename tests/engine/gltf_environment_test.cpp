// The glTF scene's "gi" extras (docs/scene-format.md): a sky and a sun, loaded into
// SceneAsset::environment (the sun as a directional light on a node of its own), written
// back by engine::write_gltf, and refused with a message naming what is wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include <engine/gltf.h>
#include <engine/sky.h>

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
  const fs::path path = with_scene_gi("sky_sun.gltf", json::parse(R"({"sky": {"radiance": [0.5, 0.6, 0.9]},
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
  auto a = engine::load_gltf(with_scene_gi("roundtrip_in.gltf", json::parse(R"({"sky": {"radiance": [1, 2, 3]},
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
      {R"({"sky": {}})", "needs 'radiance' or 'zenith', 'horizon' and 'ground'"},
      {R"({"sky": {"zenith": [1, 1, 1], "horizon": [1, 1, 1]}})", "needs all of 'zenith', 'horizon' and 'ground'"},
      {R"({"sky": {"zenith": [1, 1, 1], "horizon": [1, 1, 1], "ground": [0, -1, 0]}})", "'ground' has a negative"},
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

// A gradient sky (engine/sky.h): zenith, horizon and ground radiance, alone or added to a
// uniform radiance; loaded, evaluated as documented and written back.
TEST(GltfEnvironment, GradientSkyLoadsEvaluatesAndRoundTrips) {
  auto a = engine::load_gltf(with_scene_gi(
      "gradient.gltf",
      json::parse(R"({"sky": {"zenith": [0.2, 0.4, 1.0], "horizon": [0.8, 0.9, 1.0], "ground": [0.1, 0.1, 0.05]}})")));
  ASSERT_TRUE(a) << a.error().to_string();
  const engine::Environment& env = a->environment;
  EXPECT_EQ(env.sky_radiance, glm::vec3(0.0f));
  EXPECT_EQ(env.sky_gradient.zenith, glm::vec3(0.2f, 0.4f, 1.0f));
  EXPECT_EQ(env.sky_gradient.horizon, glm::vec3(0.8f, 0.9f, 1.0f));
  EXPECT_EQ(env.sky_gradient.ground, glm::vec3(0.1f, 0.1f, 0.05f));
  const auto at = [&](glm::vec3 d) {
    return engine::sky_radiance(env.sky_radiance, env.sky_gradient, glm::normalize(d));
  };
  const auto near = [](glm::vec3 p, glm::vec3 q) { return glm::length(p - q) < 1e-6f; };
  EXPECT_TRUE(near(at({0, 1, 0}), env.sky_gradient.zenith));
  EXPECT_TRUE(near(at({1, 0, 0}), env.sky_gradient.horizon));
  EXPECT_TRUE(near(at({0, -1, 0}), env.sky_gradient.ground));
  const glm::vec3 up30 = at({std::cos(0.5235988f), std::sin(0.5235988f), 0});  // elevation 30 degrees: halfway
  EXPECT_NEAR(up30.x, 0.5f, 1e-5f);
  const glm::vec3 down30 = at({0, -std::sin(0.5235988f), std::cos(0.5235988f)});
  EXPECT_NEAR(down30.x, 0.45f, 1e-5f);

  const fs::path out = dir() / "gradient_out.gltf";
  ASSERT_TRUE(engine::write_gltf(*a, out));
  auto b = engine::load_gltf(out);
  ASSERT_TRUE(b) << b.error().to_string();
  EXPECT_EQ(b->environment.sky_gradient, env.sky_gradient);
  EXPECT_EQ(b->environment.sky_radiance, glm::vec3(0.0f));

  auto both = engine::load_gltf(with_scene_gi(
      "gradient_plus_uniform.gltf",
      json::parse(
          R"({"sky": {"radiance": [1, 1, 1], "zenith": [1, 0, 0], "horizon": [0, 0, 0], "ground": [0, 0, 0]}})")));
  ASSERT_TRUE(both) << both.error().to_string();
  EXPECT_EQ(engine::sky_radiance(both->environment.sky_radiance, both->environment.sky_gradient, {0, 1, 0}),
            glm::vec3(2, 1, 1));
}

// The closed forms of engine/sky.h (mean radiance, irradiance of any normal) against numeric
// integration over the sphere.
TEST(GltfEnvironment, GradientSkyIrradianceFormulasMatchNumericIntegration) {
  const glm::vec3 uniform(0.3f, 0.0f, 0.0f);
  const engine::SkyGradient g{
      .zenith = {0.2f, 1.0f, 0.0f}, .horizon = {0.8f, 0.1f, 0.5f}, .ground = {0.1f, 0.6f, 2.0f}};
  const int n = 400;  // midpoint rule over (theta, phi)
  const double pi = 3.141592653589793;
  const glm::dvec3 normals[] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0.6, 0.8, 0}, {0, -0.6, 0.8}};
  glm::dvec3 mean(0.0);
  std::vector<glm::dvec3> irradiance(std::size(normals), glm::dvec3(0.0));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const double theta = (i + 0.5) * pi / n, phi = (j + 0.5) * pi / n;
      const double dw = std::sin(theta) * (pi / n) * (pi / n);
      const glm::dvec3 d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      const glm::dvec3 l(engine::sky_radiance(uniform, g, glm::vec3(d)));
      mean += l * dw / (4.0 * pi);
      for (std::size_t k = 0; k < std::size(normals); ++k)
        irradiance[k] += l * std::max(0.0, glm::dot(d, normals[k])) * dw;
    }
  const glm::vec3 m = engine::sky_mean_radiance(uniform, g);
  const glm::vec3 up = engine::sky_irradiance_up(uniform, g);

  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(static_cast<double>(m[c]), mean[c], 1e-3);
    EXPECT_NEAR(static_cast<double>(up[c]), irradiance[0][c], 2e-3 * (1.0 + irradiance[0][c]));
    for (std::size_t k = 0; k < std::size(normals); ++k) {
      const double e = static_cast<double>(engine::sky_irradiance(uniform, g, glm::vec3(normals[k]))[c]);
      EXPECT_NEAR(e, irradiance[k][c], 2e-3 * (1.0 + irradiance[k][c])) << "normal " << k << " channel " << c;
    }
    EXPECT_NEAR(static_cast<double>(engine::sky_irradiance(uniform, g, {0, 1, 0})[c]), static_cast<double>(up[c]),
                1e-4);
  }
}

// The command-line form of the sky (gi-bake, gi-reference and gi_demo --sky): either form
// replaces the whole sky; anything malformed is refused.
TEST(GltfEnvironment, SkyTextParsesBothFormsAndRefusesMalformedOnes) {
  const auto uniform = engine::parse_sky_text("0.5,0.25,1");
  ASSERT_TRUE(uniform);
  EXPECT_EQ(uniform->uniform, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_TRUE(uniform->gradient.empty());
  const auto gradient = engine::parse_sky_text("ground:0.1,0.09,0.08;zenith:0.15,0.3,0.8;horizon:0.6,0.7,0.85");
  ASSERT_TRUE(gradient);
  EXPECT_EQ(gradient->uniform, glm::vec3(0.0f));
  EXPECT_EQ(gradient->gradient.zenith, glm::vec3(0.15f, 0.3f, 0.8f));
  EXPECT_EQ(gradient->gradient.horizon, glm::vec3(0.6f, 0.7f, 0.85f));
  EXPECT_EQ(gradient->gradient.ground, glm::vec3(0.1f, 0.09f, 0.08f));
  for (const char* bad : {"", "1,1", "1,1,1,1", "1,,1", "1,-1,1", "nan,1,1", "inf,1,1", "1,1,x", "zenith:1,1,1",
                          "zenith:1,1,1;horizon:1,1,1", "zenith:1,1,1;horizon:1,1,1;ground:1,1,1;zenith:1,1,1",
                          "zenith:1,1,1;horizon:1,1,1;sky:1,1,1", "zenith:1,1,1;horizon:1,1,1;ground:1,1",
                          "zenith:1,1,1;horizon:1,1,1;ground:1,1,1;", "1,1,1;zenith:1,1,1"})
    EXPECT_FALSE(engine::parse_sky_text(bad)) << "'" << bad << "'";
}
