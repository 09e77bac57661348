// `--sun` (tools/common/sun_option.h): the scene extras' gi.sun in one argument, the same
// form for gi-bake and gi-frame-truth; malformed forms are refused, never half applied.
#include "sun_option.h"

#include <gtest/gtest.h>

#include <numbers>

TEST(SunOption, DirectionAndIrradianceInAnyOrderWithTheDefaultDisc) {
  const auto sun = tools::parse_sun("irradiance:700,650,600;direction:0.3,-1,0.2");
  ASSERT_TRUE(sun);
  EXPECT_EQ(sun->direction, glm::vec3(0.3f, -1.0f, 0.2f));
  EXPECT_EQ(sun->irradiance, glm::vec3(700.0f, 650.0f, 600.0f));
  EXPECT_FLOAT_EQ(sun->angular_radius_rad, 0.27f * std::numbers::pi_v<float> / 180.0f) << "the loader's default";
  const auto point = tools::parse_sun("direction:0,-1,0;irradiance:1,1,1;angular_radius_deg:0");
  ASSERT_TRUE(point);
  EXPECT_EQ(point->angular_radius_rad, 0.0f);
}

TEST(SunOption, MalformedSunsAreRefusedAndLeaveTheSceneAlone) {
  for (const char* text :
       {"", "0,-1,0", "direction:0,-1,0", "irradiance:1,1,1", "direction:0,0,0;irradiance:1,1,1",
        "direction:0,-1;irradiance:1,1,1", "direction:0,-1,0;irradiance:1,-1,1",
        "direction:0,-1,0;irradiance:1,1,1;angular_radius_deg:46", "direction:0,-1,0;irradiance:1,1,1;direction:0,-1,0",
        "direction:0,-1,0;irradiance:a,1,1", "direction:0,-1,0;irradiance:1,1,1;moon:1"}) {
    EXPECT_FALSE(tools::parse_sun(text)) << text;
    engine::SceneAsset a;
    EXPECT_FALSE(tools::set_sun(a, text)) << text;
    EXPECT_TRUE(a.lights.empty() && a.nodes.empty()) << text;
  }
}

TEST(SunOption, SetSunGivesTheSceneASunLight) {
  engine::SceneAsset a;
  ASSERT_TRUE(tools::set_sun(a, "direction:0,-1,0;irradiance:800,700,600"));
  ASSERT_EQ(a.lights.size(), 1u);
  EXPECT_EQ(a.environment.sun_light, 0);
  EXPECT_FLOAT_EQ(a.lights[0].light.intensity, 800.0f);
}
