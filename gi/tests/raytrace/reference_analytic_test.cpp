// The reference path tracer against closed-form answers: furnace, inverse-square and cosine
// laws, spot cones, a uniform sky, and the energy balance of the Cornell box.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include <engine/sky.h>

#include "core/random.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/path_tracer.h"
#include "raytrace/reference_render.h"
#include "reference_scenes.h"

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr double kPiD = std::numbers::pi;

gi::ReferenceSettings settings(int spp, int bounces = -1) {
  gi::ReferenceSettings s;
  s.samples_per_pixel = spp;
  s.max_bounces = bounces;
  s.threads = 2;
  return s;
}

std::vector<gi::SurfacePoint> points_on_floor(float y, int n, float half) {
  std::vector<gi::SurfacePoint> pts;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      pts.push_back({{-half + 2 * half * (i + 0.5f) / n, y, -half + 2 * half * (j + 0.5f) / n}, {0, 1, 0}});
  return pts;
}

// Closed furnace: every wall emits Le and reflects albedo rho, so radiance is Le / (1 - rho)
// everywhere; irradiance is pi Le (direct) + pi Le rho / (1 - rho) (indirect).
TEST(ReferenceFurnace, RadianceIsEmissionOverOneMinusAlbedo) {
  for (float rho : {0.5f, 0.8f}) {
    const gi::ReferenceScene s = reftest::furnace_scene(reftest::lambert(rho, glm::vec3(1.0f)));
    gi::PinholeCamera cam;
    cam.width = cam.height = 8;
    cam.yfov_rad = 1.2f;
    auto img = gi::render_reference(s, cam, settings(512));
    ASSERT_TRUE(img) << img.error().to_string();
    double sum = 0.0;
    for (int i = 0; i < 64; ++i) {
      const float v = img->pixels[4 * static_cast<std::size_t>(i)];
      // Each pixel (512 paths, Russian roulette) within 15%: no structured bias in corners.
      EXPECT_NEAR(v, 1.0f / (1.0f - rho), 0.15f / (1.0f - rho)) << "pixel " << i << " rho " << rho;
      sum += static_cast<double>(v);
    }
    EXPECT_NEAR(sum / 64.0, 1.0 / (1.0 - static_cast<double>(rho)), 0.01 / (1.0 - static_cast<double>(rho)));

    const auto pts = points_on_floor(-1.0f, 4, 0.8f);
    auto e = gi::estimate_irradiance(s, pts, settings(1024));
    ASSERT_TRUE(e) << e.error().to_string();
    double direct = 0.0, indirect = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      direct += static_cast<double>(e->direct[i].x);
      indirect += static_cast<double>(e->indirect[i].x);
    }
    direct /= static_cast<double>(pts.size());
    indirect /= static_cast<double>(pts.size());
    EXPECT_NEAR(direct, kPiD, 0.01 * kPiD);
    const double expected_indirect = kPiD * static_cast<double>(rho) / (1.0 - static_cast<double>(rho));
    EXPECT_NEAR(indirect, expected_indirect, 0.01 * (kPiD + expected_indirect));
  }
}

// A point light of intensity I at height h over a plane: E = I cos / d^2 = I h / d^3 and the
// plane, which cannot see itself, reflects L = rho / pi E. Both exact (delta light).
TEST(ReferencePointLight, InverseSquareAndCosineLaw) {
  gi::ReferenceScene s = reftest::plane_scene(0.5f);
  const float h = 2.0f, intensity = 10.0f;
  s.lights.push_back(reftest::point_light({0, h, 0}, intensity));
  std::vector<gi::SurfacePoint> pts;
  for (float x : {0.0f, 0.5f, 1.0f, 2.0f, 4.0f, 7.0f}) pts.push_back({{x, 0, 0.3f * x}, {0, 1, 0}});
  auto e = gi::estimate_irradiance(s, pts, settings(4));
  ASSERT_TRUE(e) << e.error().to_string();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const float d = glm::length(glm::vec3(0, h, 0) - pts[i].position_m);
    const float expected = intensity * h / (d * d * d);
    EXPECT_NEAR(e->direct[i].y, expected, 1e-4f * expected) << "x = " << pts[i].position_m.x;
    EXPECT_EQ(e->indirect[i], glm::vec3(0.0f));
  }

  auto index = gi::index_reference_scene(s);
  auto caster = gi::make_embree_ray_caster(s.geometry);
  ASSERT_TRUE(index && caster);
  const gi::PathTracer pt(s, *index, **caster, {});
  gi::Pcg32 rng = gi::Pcg32::for_item(1, 0);
  const glm::vec3 eye(1.0f, 3.0f, 0.5f), target(1.5f, 0.0f, -1.0f);
  // Diffuse radiance does not depend on the view; average the BRDF-sampling noise away: the
  // only randomness is the continuation ray, which escapes (no sky) and adds nothing.
  const glm::vec3 L = pt.radiance(gi::Ray{eye, 0.0f, glm::normalize(target - eye)}, rng);
  const float d = glm::length(glm::vec3(0, h, 0) - target);
  EXPECT_NEAR(L.x, 0.5f / kPi * intensity * h / (d * d * d), 1e-5f);
}

// A spot light: full intensity inside the inner cone, none outside the outer one, the
// renderer's smoothstep in between.
TEST(ReferenceSpotLight, ConeFalloffMatchesTheRenderer) {
  gi::ReferenceScene s = reftest::plane_scene(0.5f);
  gi::ReferenceLight l = reftest::point_light({0, 2, 0}, 8.0f);
  l.type = gi::ReferenceLight::Type::Spot;
  l.direction = {0, -1, 0};
  l.cos_inner = std::cos(0.3f);
  l.cos_outer = std::cos(0.5f);
  s.lights.push_back(l);
  const float r_inner = 2.0f * std::tan(0.25f), r_mid = 2.0f * std::tan(0.4f), r_out = 2.0f * std::tan(0.6f);
  const std::vector<gi::SurfacePoint> pts = {
      {{r_inner, 0, 0}, {0, 1, 0}}, {{0, 0, r_mid}, {0, 1, 0}}, {{-r_out, 0, 0}, {0, 1, 0}}};
  auto e = gi::estimate_irradiance(s, pts, settings(1));
  ASSERT_TRUE(e);
  const auto point_e = [](float r) {
    const float d = std::sqrt(4.0f + r * r);
    return 8.0f * 2.0f / (d * d * d);
  };
  EXPECT_NEAR(e->direct[0].x, point_e(r_inner), 1e-4f);
  const float t = (std::cos(0.4f) - l.cos_outer) / (l.cos_inner - l.cos_outer);
  EXPECT_NEAR(e->direct[1].x, point_e(r_mid) * t * t * (3 - 2 * t), 1e-4f);
  EXPECT_EQ(e->direct[2].x, 0.0f);
}

// A Lambertian plane under a uniform sky of radiance L: E = pi L, outgoing radiance rho L.
// A huge black wall beside a point hides half its (cosine-weighted) sky: E = pi L / 2.
TEST(ReferenceSky, LambertianPlaneUnderUniformSky) {
  gi::ReferenceScene s = reftest::plane_scene(0.6f);
  s.sky_radiance = glm::vec3(1.5f);
  const auto pts = points_on_floor(0.0f, 3, 5.0f);
  auto e = gi::estimate_irradiance(s, pts, settings(16));
  ASSERT_TRUE(e);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(e->direct[i].x, kPi * 1.5f, 1e-4f);
    EXPECT_EQ(e->indirect[i].x, 0.0f);
  }
  gi::PinholeCamera cam;
  cam.width = cam.height = 4;
  cam.yfov_rad = 0.5f;
  cam.camera_to_world = glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0, 0, -1, 0), glm::vec4(0, 1, 0, 0),
                                  glm::vec4(0, 3, 0, 1));  // looking straight down
  auto img = gi::render_reference(s, cam, settings(8));
  ASSERT_TRUE(img);
  for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(img->pixels[4 * i], 0.6f * 1.5f, 1e-5f);

  gi::RtGeometry wall;
  reftest::add_quad(wall, {0.001f, -1.0f, -1000.0f}, {0, 0, 2000.0f}, {0, 1000.0f, 0});
  reftest::add_geometry(s, std::move(wall), reftest::lambert(0.0f));
  const std::vector<gi::SurfacePoint> foot(16, gi::SurfacePoint{{0, 0, 0}, {0, 1, 0}});
  gi::ReferenceSettings many = settings(4096);
  auto half = gi::estimate_irradiance(s, foot, many);
  ASSERT_TRUE(half);
  double mean = 0.0;
  for (const glm::vec3& v : half->direct) mean += static_cast<double>(v.x) / 16.0;
  EXPECT_NEAR(mean, kPiD * 1.5 / 2.0, 0.01 * kPiD * 1.5);
}

// A gradient sky (engine/sky.h) over a Lambertian plane: E = pi/3 horizon + 2 pi/3 zenith
// (the plane hides the ground half), outgoing rho E / pi; a camera looking straight up sees
// the zenith, one looking level the horizon.
TEST(ReferenceSky, LambertianPlaneUnderGradientSky) {
  gi::ReferenceScene s = reftest::plane_scene(0.6f);
  s.sky_gradient = {.zenith = {0.2f, 0.4f, 1.0f}, .horizon = {1.0f, 0.9f, 0.7f}, .ground = {5.0f, 5.0f, 5.0f}};
  const glm::vec3 expected = engine::sky_irradiance_up(glm::vec3(0.0f), s.sky_gradient);
  const auto pts = points_on_floor(0.0f, 4, 5.0f);
  auto e = gi::estimate_irradiance(s, pts, settings(4096));
  ASSERT_TRUE(e);
  for (int c = 0; c < 3; ++c) {
    double mean = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i)
      mean += static_cast<double>(e->direct[i][c]) / static_cast<double>(pts.size());
    EXPECT_NEAR(mean, static_cast<double>(expected[c]), 0.005 * static_cast<double>(expected[c])) << "channel " << c;
  }
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(e->indirect[i], glm::vec3(0.0f));

  gi::PinholeCamera cam;
  cam.width = cam.height = 1;
  cam.yfov_rad = 0.002f;
  cam.camera_to_world = glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0, 0, 1, 0), glm::vec4(0, -1, 0, 0),
                                  glm::vec4(0, 3, 0, 1));  // looking straight up (-Z = +Y)
  auto up = gi::render_reference(s, cam, settings(4));
  ASSERT_TRUE(up);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(up->pixels[static_cast<std::size_t>(c)], s.sky_gradient.zenith[c], 1e-3f);
  cam.camera_to_world = glm::mat4(1.0f);
  cam.camera_to_world[3] = glm::vec4(0, 3, 0, 1);  // looking along -Z, level
  auto level = gi::render_reference(s, cam, settings(4));
  ASSERT_TRUE(level);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(level->pixels[static_cast<std::size_t>(c)], s.sky_gradient.horizon[c], 1e-2f);
}

}  // namespace
