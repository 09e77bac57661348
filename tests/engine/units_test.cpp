// Light units (engine/units.h): photometric glTF values to the engine's radiometric ones,
// and a KHR_lights_punctual file loaded through engine::load_gltf.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <engine/gltf.h>
#include <engine/units.h>

namespace {

namespace fs = std::filesystem;
using namespace engine::units;

TEST(Units, CandelaAndLuxUse683LumensPerWatt) {
  static_assert(candela_to_w_per_sr(683.0f) == 1.0f);
  static_assert(lux_to_w_per_m2(683.0f) == 1.0f);
  EXPECT_FLOAT_EQ(candela_to_w_per_sr(100.0f), 100.0f / 683.0f);
  EXPECT_FLOAT_EQ(lux_to_w_per_m2(100000.0f), 100000.0f / 683.0f);  // direct sunlight, ~146 W/m^2
  EXPECT_FLOAT_EQ(candela_to_w_per_sr(0.0f), 0.0f);
}

TEST(Units, ConversionsRoundTrip) {
  for (float v : {1e-3f, 0.5f, 1.0f, 42.0f, 683.0f, 1e5f}) {
    EXPECT_NEAR(w_per_sr_to_candela(candela_to_w_per_sr(v)), v, 1e-6f * v);
    EXPECT_NEAR(w_per_m2_to_lux(lux_to_w_per_m2(v)), v, 1e-6f * v);
  }
}

TEST(Units, KhrLightIntensitiesConvertOnLoad) {
  const fs::path dir = fs::path(testing::TempDir()) / "gi_units_test";
  fs::create_directories(dir);
  const fs::path path = dir / "lights.gltf";
  std::ofstream(path) << R"({
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "point", "intensity": 800},
      {"type": "spot", "intensity": 50, "spot": {}},
      {"type": "directional", "intensity": 3.5}]}},
    "nodes": [{"extensions": {"KHR_lights_punctual": {"light": 0}}},
              {"extensions": {"KHR_lights_punctual": {"light": 1}}},
              {"extensions": {"KHR_lights_punctual": {"light": 2}}}]})";
  auto r = engine::load_gltf(path);
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  ASSERT_EQ(r->lights.size(), 3u);
  // Back to the file's photometric values within float rounding.
  EXPECT_NEAR(w_per_sr_to_candela(r->lights[0].light.intensity), 800.0f, 1e-3f);
  EXPECT_NEAR(w_per_sr_to_candela(r->lights[1].light.intensity), 50.0f, 1e-4f);
  EXPECT_NEAR(w_per_m2_to_lux(r->lights[2].light.intensity), 3.5f, 1e-5f);
  EXPECT_NEAR(r->lights[0].light.intensity, 1.1713031f, 1e-6f);  // 800 / 683 W/sr
}

}  // namespace
