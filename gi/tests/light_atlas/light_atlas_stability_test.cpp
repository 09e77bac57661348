// The light-atlas baker on hard cases: albedo close to 1, a light touching a wall, tiny and
// huge scenes, thread-count independence, lights that move, and the incremental update.
#include <gtest/gtest.h>
#include <engine/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "light_atlas/light_atlas.h"
#include "light_atlas_scenes.h"
#include "raytrace/scene_adapter.h"
#include "transport/vpl_set.h"

namespace {

gi::LightAtlasSettings small_settings() {
  gi::LightAtlasSettings s;
  s.texels_per_metre = 8.0f;
  s.vpl_count = 300;
  s.bounces = 32;
  s.unshot_threshold = 0.0f;
  return s;
}

struct AtlasSummary {
  double mean = 0.0;  // mean green irradiance over valid texels
  double max = 0.0;
  bool finite = true;
  bool non_negative = true;
};

AtlasSummary summarize(const gi::LightAtlasBake& b) {
  AtlasSummary s;
  std::size_t n = 0;
  for (std::size_t t = 0; t < b.irradiance.size(); ++t) {
    const glm::vec3 e = b.irradiance[t];
    s.finite = s.finite && std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z);
    s.non_negative = s.non_negative && e.x >= 0.0f && e.y >= 0.0f && e.z >= 0.0f;
    if (!b.valid[t]) continue;
    s.mean += static_cast<double>(e.y);
    s.max = std::max(s.max, static_cast<double>(e.y));
    ++n;
  }
  s.mean /= static_cast<double>(std::max<std::size_t>(n, 1));
  return s;
}

// The largest radiosity of any VPL patch, E_i / A_i: no point inside the scene can receive
// more indirect irradiance than a whole sky of it.
double max_radiosity(const gi::LightAtlasBake& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < b.vpls.size(); ++i)
    m = std::max(m, static_cast<double>(b.vpl_power[i].y / b.vpls.area_m2[i]));
  return m;
}

TEST(LightAtlasStability, AlbedoNearOneKeepsTheSeries) {
  const engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.95f, {0.3f, -0.2f, 0.1f}, 5.0f));
  const double rho = double{
      engine::gltf_hemispherical_albedo(gi::reference_material(gi::bake_input_from(scene).materials[0]).brdf).sum().y};
  gi::LightAtlasSettings s = small_settings();
  s.bounces = 64;
  const gi::LightAtlasBake b = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
  double reflected = 0.0;
  for (const glm::vec3& e : b.vpl_power) reflected += static_cast<double>(e.y);
  // 64 bounces of the series rho^k: the truncated sum, not the infinite one.
  const double phi = 4.0 * 3.14159265358979 * 5.0;
  const double expected = phi * rho * (1.0 - std::pow(rho, 64.0)) / (1.0 - rho);
  std::printf("albedo %.4f: reflected %.2f W, truncated series %.2f W (ratio %.4f)\n", rho, reflected, expected,
              reflected / expected);
  EXPECT_NEAR(reflected / expected, 1.0, 0.03);
  const AtlasSummary a = summarize(b);
  EXPECT_TRUE(a.finite);
  EXPECT_TRUE(a.non_negative);
  EXPECT_LE(a.max, 1.5 * max_radiosity(b));
}

TEST(LightAtlasStability, LightOneMillimetreFromAWallIsBounded) {
  // The box spans [-1, 1]^3: the light sits 1 mm from the wall x = 1.
  const engine::Scene near = engine::instantiate(latest::closed_box(2.0f, 0.5f, {0.999f, 0.0f, 0.0f}, 5.0f));
  const engine::Scene mid = engine::instantiate(latest::closed_box(2.0f, 0.5f, {0.0f, 0.0f, 0.0f}, 5.0f));
  const gi::LightAtlasBake a = gi::bake_light_atlas(gi::bake_input_from(near), small_settings()).value();
  const gi::LightAtlasBake b = gi::bake_light_atlas(gi::bake_input_from(mid), small_settings()).value();
  const AtlasSummary sa = summarize(a), sb = summarize(b);
  std::printf("light 1 mm from a wall: mean %.4f max %.4f (max radiosity %.4f); centred: mean %.4f max %.4f\n", sa.mean,
              sa.max, max_radiosity(a), sb.mean, sb.max);
  EXPECT_TRUE(sa.finite);
  EXPECT_TRUE(sa.non_negative);
  // No texel spikes: nothing exceeds the brightest patch's radiosity (times a margin for the
  // point sampling of the patches).
  EXPECT_LE(sa.max, 1.5 * max_radiosity(a));
  // Same power in a closed box: the mean indirect irradiance barely depends on where the
  // light is (each wall reflects half of what it gets wherever it comes from).
  EXPECT_NEAR(sa.mean / sb.mean, 1.0, 0.1);
}

TEST(LightAtlasStability, TinyAndHugeScenesScaleExactly) {
  // Same power, box side s: irradiance scales as 1 / s^2.
  double scaled[3];
  const float sides[3] = {0.01f, 1.0f, 1000.0f};
  for (int k = 0; k < 3; ++k) {
    const float side = sides[k];
    const engine::Scene scene =
        engine::instantiate(latest::closed_box(side, 0.6f, glm::vec3(0.1f, -0.2f, 0.15f) * side, 5.0f));
    gi::LightAtlasSettings s = small_settings();
    s.texels_per_metre = 8.0f / side;
    const gi::LightAtlasBake b = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
    const AtlasSummary a = summarize(b);
    EXPECT_TRUE(a.finite && a.non_negative) << "side " << side;
    scaled[k] = a.mean * static_cast<double>(side) * static_cast<double>(side);
    std::printf("side %g m: mean indirect irradiance x side^2 = %.5f\n", double{side}, scaled[k]);
  }
  EXPECT_NEAR(scaled[0] / scaled[1], 1.0, 0.02);
  EXPECT_NEAR(scaled[2] / scaled[1], 1.0, 0.02);
}

TEST(LightAtlasStability, BitIdenticalForAnyThreadCount) {
  const engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.7f, {0.3f, -0.2f, 0.1f}, 5.0f));
  gi::LightAtlasSettings s = small_settings();
  s.threads = 1;
  const gi::LightAtlasBake one = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
  s.threads = 2;
  const gi::LightAtlasBake two = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
  s.threads = 5;
  const gi::LightAtlasBake five = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
  EXPECT_TRUE(one.irradiance == two.irradiance);
  EXPECT_TRUE(one.irradiance == five.irradiance);
  EXPECT_TRUE(one.vpl_power == five.vpl_power);
}

TEST(LightAtlasStability, MovingLightsAreNotBaked) {
  engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.6f, {0.3f, -0.2f, 0.1f}, 5.0f));
  const engine::Entity lamp = engine::find_by_name(scene.registry, "lamp");
  ASSERT_FALSE(lamp.is_null());
  scene.registry.write<engine::Light>(lamp).moves = true;
  const gi::LightAtlasBake b = gi::bake_light_atlas(gi::bake_input_from(scene), small_settings()).value();
  EXPECT_EQ(summarize(b).max, 0.0);
}

TEST(LightAtlasIncremental, ThresholdZeroEqualsFullRebakeAndThresholdSkipsVpls) {
  engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.6f, {0.3f, -0.2f, 0.1f}, 5.0f));
  gi::LightAtlasSettings s = small_settings();
  s.bounces = 8;
  gi::LightAtlasBake bake = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
  gi::LightAtlasBake coarse = bake;

  // The lamp gets brighter and moves a little (a static light edited between bakes).
  const engine::Entity lamp = engine::find_by_name(scene.registry, "lamp");
  scene.registry.write<engine::Light>(lamp).intensity = 8.0f;
  scene.registry.write<engine::WorldTransform>(lamp).matrix[3] = glm::vec4(0.2f, -0.1f, 0.1f, 1.0f);
  const gi::LightAtlasBake full = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();

  const auto update = gi::update_light_atlas(gi::bake_input_from(scene), bake, 0.0f);
  ASSERT_TRUE(update) << update.error().to_string();
  double err = 0.0, norm = 0.0;
  for (std::size_t t = 0; t < full.irradiance.size(); ++t) {
    if (!full.valid[t]) continue;
    const glm::vec3 d = bake.irradiance[t] - full.irradiance[t];
    err += static_cast<double>(glm::dot(d, d));
    norm += static_cast<double>(glm::dot(full.irradiance[t], full.irradiance[t]));
  }
  EXPECT_LT(std::sqrt(err / norm), 1e-4);
  EXPECT_EQ(update->reshot_vpls, bake.vpls.size());

  const auto partial = gi::update_light_atlas(gi::bake_input_from(scene), coarse, 0.05f);
  ASSERT_TRUE(partial);
  err = 0.0;
  for (std::size_t t = 0; t < full.irradiance.size(); ++t) {
    if (!full.valid[t]) continue;
    const glm::vec3 d = coarse.irradiance[t] - full.irradiance[t];
    err += static_cast<double>(glm::dot(d, d));
  }
  std::printf("incremental update, threshold 0.05: %zu of %zu VPLs re-shot, rel RMSE vs full re-bake %.4f\n",
              partial->reshot_vpls, coarse.vpls.size(), std::sqrt(err / norm));
  EXPECT_LT(partial->reshot_vpls, coarse.vpls.size());
  EXPECT_LT(std::sqrt(err / norm), 0.1);
}

}  // namespace
