// The reference path tracer on the measured Cornell box (assets/cornell_box.gltf): energy
// balance, determinism across thread counts, and its errors.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/reference.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/random.h"
#include "raytrace/reference_render.h"
#include "raytrace/scene_adapter.h"
#include "reference_scenes.h"

namespace {

engine::Scene cornell_box() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset) << asset.error().to_string();
  return engine::instantiate(std::move(asset.value()));
}

// Emitted power = absorbed power + power leaving through the open front. Absorbed power is
// sum (1 - albedo) E dA over every surface (E from the path tracer at area-stratified
// points); the power leaving is the irradiance on the opening from the inside. Materials
// are made purely Lambertian so that absorption is (1 - albedo) E exactly.
TEST(ReferenceCornellBox, EnergyBalance) {
  const engine::Scene scene = cornell_box();
  gi::ReferenceScene s = gi::reference_scene_from(gi::bake_input_from(scene));
  for (gi::ReferenceMaterial& m : s.materials) m.brdf = engine::gltf_lambertian(m.brdf.base_color);
  auto index = gi::index_reference_scene(s);
  ASSERT_TRUE(index) << index.error().to_string();
  ASSERT_FALSE(index->emitters.triangle.empty());

  glm::dvec3 emitted(0.0);
  for (std::uint32_t t : index->emitters.triangle) {
    const gi::ShadingTriangle& tri = index->triangles[t];
    emitted += glm::dvec3(s.materials[tri.material].emission) * (std::numbers::pi * static_cast<double>(tri.area_m2));
  }

  std::vector<gi::SurfacePoint> points;
  std::vector<glm::dvec3> weight;  // area x (1 - albedo) per point
  for (std::size_t t = 0; t < index->triangles.size(); ++t) {
    const gi::ShadingTriangle& tri = index->triangles[t];
    const int n = std::max(8, static_cast<int>(tri.area_m2 * 8000.0f));
    gi::Pcg32 rng = gi::Pcg32::for_item(99, t);
    for (int i = 0; i < n; ++i) {
      float u = rng.next_float(), v = rng.next_float();
      if (u + v > 1.0f) {
        u = 1.0f - u;
        v = 1.0f - v;
      }
      points.push_back({tri.p0 + u * tri.e1 + v * tri.e2, tri.face_normal});
      weight.push_back(glm::dvec3(1.0f - s.materials[tri.material].brdf.base_color) *
                       (static_cast<double>(tri.area_m2) / n));
    }
  }
  // The open front (z = 0): irradiance arriving from inside the box.
  const int grid = 24;
  const double opening_area = 0.5544 * 0.5488;  // mean width of the front edge x height
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      points.push_back({{0.5544f * (i + 0.5f) / grid, 0.5488f * (j + 0.5f) / grid, 0.0f}, {0, 0, 1}});
      weight.push_back(glm::dvec3(opening_area / (grid * grid)));
    }

  gi::ReferenceSettings settings;
  settings.samples_per_pixel = 64;
  settings.threads = 2;
  auto e = gi::estimate_irradiance(s, points, settings);
  ASSERT_TRUE(e) << e.error().to_string();
  glm::dvec3 out(0.0);
  for (std::size_t i = 0; i < points.size(); ++i) out += weight[i] * glm::dvec3(e->direct[i] + e->indirect[i]);
  std::printf("Cornell box: (absorbed + escaped) / emitted = %.4f %.4f %.4f\n", out.x / emitted.x, out.y / emitted.y,
              out.z / emitted.z);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c] / emitted[c], 1.0, 0.02) << "channel " << c;
}

TEST(ReferenceCornellBox, BitIdenticalForAnyThreadCount) {
  const engine::Scene scene = cornell_box();
  gi::ReferenceSettings s;
  s.samples_per_pixel = 4;
  std::vector<float> first;
  for (unsigned threads : {1u, 2u, 3u}) {
    s.threads = threads;
    auto img = gi::render_reference_image(scene, engine::find_camera(scene.registry), 24, 20, s);
    ASSERT_TRUE(img) << img.error().to_string();
    if (first.empty()) first = img->pixels;
    EXPECT_EQ(img->pixels, first) << threads << " threads";
  }
}

TEST(ReferenceCornellBox, ProgressIsReportedAndCancelStops) {
  const engine::Scene scene = cornell_box();
  gi::ReferenceSettings s;
  s.samples_per_pixel = 1;
  std::vector<double> seen;
  s.progress = [&](double f) {
    seen.push_back(f);
    return true;
  };
  ASSERT_TRUE(gi::render_reference_image(scene, engine::find_camera(scene.registry), 64, 64, s));
  ASSERT_GE(seen.size(), 2u);
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i], seen[i - 1]);

  s.progress = [](double) { return false; };
  auto cancelled = gi::render_reference_image(scene, engine::find_camera(scene.registry), 64, 64, s);
  ASSERT_FALSE(cancelled);
  EXPECT_NE(cancelled.error().message.find("cancelled"), std::string::npos);
}

TEST(ReferenceErrors, BadSettingsAndInputsAreReported) {
  const engine::Scene scene = cornell_box();
  const engine::Entity cam = engine::find_camera(scene.registry);
  gi::ReferenceSettings s;
  s.samples_per_pixel = 0;
  auto a = gi::render_reference_image(scene, cam, 8, 8, s);
  ASSERT_FALSE(a);
  EXPECT_NE(a.error().message.find("samples_per_pixel"), std::string::npos);
  s.samples_per_pixel = 1;
  auto b = gi::render_reference_image(scene, cam, 0, 8, s);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("image size"), std::string::npos);
  auto c = gi::render_reference_image(scene, engine::Entity{}, 8, 8, s);
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message.find("camera"), std::string::npos);

  const std::vector<gi::SurfacePoint> bad = {{{NAN, 0, 0}, {0, 1, 0}}};
  auto d = gi::reference_irradiance(scene, bad, s);
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find("surface point 0"), std::string::npos);

  gi::ReferenceScene broken = reftest::plane_scene(0.5f);
  broken.geometry.geometries[0].indices[2] = 99;
  auto e = gi::estimate_irradiance(broken, std::vector<gi::SurfacePoint>{{{0, 0, 0}, {0, 1, 0}}}, s);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().to_string().find("index out of range"), std::string::npos);

  gi::ReferenceScene nan_light = reftest::plane_scene(0.5f);
  nan_light.lights.push_back(reftest::point_light({0, NAN, 0}, 1.0f));
  auto f = gi::estimate_irradiance(nan_light, std::vector<gi::SurfacePoint>{{{0, 0, 0}, {0, 1, 0}}}, s);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().to_string().find("light 0"), std::string::npos);
}

// Hard cases stay finite: a point light 1 mm above the floor, a light inside a closed box,
// albedo 0.95, and a scene of 1 km and of 1 cm.
TEST(ReferenceStability, HardCasesStayFiniteAndBounded) {
  gi::ReferenceSettings s;
  s.samples_per_pixel = 16;
  s.threads = 2;
  const std::vector<gi::SurfacePoint> pts = {{{0.3f, 0, 0.1f}, {0, 1, 0}}, {{2.0f, 0, 0}, {0, 1, 0}}};
  gi::ReferenceScene close = reftest::plane_scene(0.95f);
  close.lights.push_back(reftest::point_light({0.3f, 0.001f, 0.1f}, 1.0f));
  auto a = gi::estimate_irradiance(close, pts, s);
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->direct[0].x, 1.0f / (0.001f * 0.001f), 1.0f);  // I / h^2 straight below
  EXPECT_TRUE(std::isfinite(a->direct[1].x));

  for (float scale : {0.01f, 1000.0f}) {
    gi::ReferenceScene box = reftest::furnace_scene(reftest::lambert(0.95f));
    for (glm::vec3& p : box.geometry.geometries[0].positions) p *= scale;
    box.lights.push_back(reftest::point_light({0, 0, 0}, scale * scale));  // E = 1 W/m^2 at the centre of a wall
    const std::vector<gi::SurfacePoint> wall = {{{0, -scale, 0}, {0, 1, 0}}};
    auto e = gi::estimate_irradiance(box, wall, s);
    ASSERT_TRUE(e) << e.error().to_string();
    EXPECT_NEAR(e->direct[0].x, 1.0f, 1e-3f) << "scale " << scale;
    // Indirect light of a closed box with albedo 0.95 is bounded by the series rho / (1 - rho)
    // times the mean direct irradiance (< 1 here): finite, positive, not absurd.
    EXPECT_GT(e->indirect[0].x, 0.0f);
    EXPECT_LT(e->indirect[0].x, 19.0f) << "scale " << scale;
  }
}

}  // namespace
