// The static world as a light source for dynamic objects (gi/src/brf/world_probes.h):
// probe irradiance from the light atlas's VPLs against the path tracer's indirect
// irradiance at free points of a closed box, and probes inside walls not leaking.
#include <engine/scene.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "brf/radiance_field.h"
#include "brf/world_probes.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas_scenes.h"
#include "raytrace/reference_render.h"
#include "raytrace/scene_adapter.h"
#include "transport/static_scene.h"

namespace {

struct BoxWithProbes {
  engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.6f, {0.3f, 0.4f, -0.2f}, 4.0f));
  gi::LightAtlasBake atlas;
  gi::WorldProbeGrid probes;
  BoxWithProbes() {
    gi::LightAtlasSettings s = gi::light_atlas_preset("medium").value();
    s.bounces = 16;
    atlas = gi::bake_light_atlas(gi::bake_input_from(scene), s).value();
    auto caster = gi::make_static_caster(gi::bake_input_from(scene)).value();
    probes = gi::bake_world_probes(*caster, atlas.vpls, atlas.vpl_power, {.spacing_m = 0.5f}).value();
  }
};

const BoxWithProbes& box_with_probes() {
  static const BoxWithProbes b;
  return b;
}

TEST(BrfWorldProbes, IrradianceAtFreePointsMatchesThePathTracer) {
  const BoxWithProbes& b = box_with_probes();
  std::vector<gi::SurfacePoint> points;
  for (glm::vec3 p : {glm::vec3(-0.4f, -0.5f, 0.3f), glm::vec3(0.2f, 0.1f, 0.45f), glm::vec3(-0.6f, 0.5f, -0.55f)})
    for (glm::vec3 n :
         {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, 1)})
      points.push_back({p, n});
  gi::ReferenceSettings rs;
  rs.samples_per_pixel = 2048;
  const auto truth =
      gi::estimate_irradiance(gi::reference_scene_from(gi::bake_input_from(b.scene)), points, rs).value();
  double err = 0.0, norm = 0.0, ours_sum = 0.0, truth_sum = 0.0;
  for (std::size_t j = 0; j < points.size(); ++j) {
    const glm::vec3 e = b.probes.irradiance(points[j].position_m, points[j].normal);
    ASSERT_TRUE(std::isfinite(e.x) && e.x >= 0.0f);
    const double d = static_cast<double>(e.x - truth.indirect[j].x);
    err += d * d;
    norm += static_cast<double>(truth.indirect[j].x) * static_cast<double>(truth.indirect[j].x);
    ours_sum += static_cast<double>(e.x);
    truth_sum += static_cast<double>(truth.indirect[j].x);
  }
  std::printf("world probes (%zu probes, %.2f m): rel RMSE %.3f, total ratio %.3f vs path tracer\n",
              b.probes.probe_count(), double{b.probes.spacing}, std::sqrt(err / norm), ours_sum / truth_sum);
  EXPECT_LT(std::sqrt(err / norm), 0.15);
  EXPECT_NEAR(ours_sum / truth_sum, 1.0, 0.1);
}

TEST(BrfWorldProbes, ProbesSitInsideTheRoomAndOutsideOnesAreInvalid) {
  const BoxWithProbes& b = box_with_probes();
  // One probe per cell of the VPLs' box, at its centre: none on the walls, all valid.
  for (std::uint8_t v : b.probes.valid) EXPECT_EQ(v, 1);
  // Near a wall (between the outer probes and the wall) the light stays that of the room,
  // against the path tracer.
  std::vector<gi::SurfacePoint> points = {{{0.0f, 0.0f, 0.0f}, {0, 1, 0}}, {{0.95f, 0.0f, 0.0f}, {0, 1, 0}},
                                          {{0.95f, 0.0f, 0.0f}, {-1, 0, 0}}, {{0.2f, -0.95f, 0.3f}, {0, 0, 1}}};
  gi::ReferenceSettings rs;
  rs.samples_per_pixel = 4096;
  const auto truth =
      gi::estimate_irradiance(gi::reference_scene_from(gi::bake_input_from(b.scene)), points, rs).value();
  for (std::size_t j = 0; j < points.size(); ++j) {
    const glm::vec3 e = b.probes.irradiance(points[j].position_m, points[j].normal);
    std::printf("probe irradiance at (%.2f %.2f %.2f): %.4f, path tracer %.4f\n", double{points[j].position_m.x},
                double{points[j].position_m.y}, double{points[j].position_m.z}, double{e.x},
                double{truth.indirect[j].x});
    EXPECT_NEAR(e.x / truth.indirect[j].x, 1.0f, 0.15f) << j;
  }
  // A grid reaching past the box (one more VPL 2 m outside it, dark): the probes outside see
  // the box's back faces and are invalid; the light inside near the wall is unchanged.
  gi::VplSet vpls = b.atlas.vpls;
  std::vector<glm::vec3> power = b.atlas.vpl_power;
  vpls.position.push_back({3.0f, 0.0f, 0.0f});
  vpls.normal.push_back({0.0f, 1.0f, 0.0f});
  vpls.albedo.push_back(glm::vec3(0.5f));
  vpls.area_m2.push_back(0.01f);
  vpls.sample_first.push_back(vpls.sample_first.empty() ? 0u : vpls.sample_first.back());
  power.push_back(glm::vec3(0.0f));
  auto caster = gi::make_static_caster(gi::bake_input_from(b.scene)).value();
  const gi::WorldProbeGrid wide = gi::bake_world_probes(*caster, vpls, power, {.spacing_m = 0.5f}).value();
  std::size_t outside = 0, invalid_outside = 0, invalid_inside = 0;
  for (int z = 0; z < wide.dims.z; ++z)
    for (int y = 0; y < wide.dims.y; ++y)
      for (int x = 0; x < wide.dims.x; ++x) {
        const glm::vec3 p = wide.origin + wide.spacing * glm::vec3(x, y, z);
        const std::size_t k = static_cast<std::size_t>(x + wide.dims.x * (y + wide.dims.y * z));
        const bool out = glm::any(glm::greaterThan(glm::abs(p), glm::vec3(1.0f)));
        outside += out ? 1 : 0;
        if (wide.valid[k] == 0) (out ? invalid_outside : invalid_inside) += 1;
      }
  EXPECT_GT(outside, 0u);
  EXPECT_EQ(invalid_outside, outside);
  EXPECT_EQ(invalid_inside, 0u);
  const glm::vec3 edge = wide.irradiance({0.95f, 0.0f, 0.0f}, {-1, 0, 0});
  EXPECT_NEAR(edge.x / truth.indirect[2].x, 1.0f, 0.2f);
  // Outside the grid the light is clamped to its border, never NaN.
  const glm::vec3 far = b.probes.irradiance({100.0f, 0.0f, 0.0f}, {0, 1, 0});
  EXPECT_TRUE(std::isfinite(far.x));
  EXPECT_EQ(b.probes.irradiance({NAN, 0.0f, 0.0f}, {0, 1, 0}), glm::vec3(0.0f));
}

TEST(BrfWorldProbes, BadInputIsAnError) {
  const engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.6f));
  auto caster = gi::make_static_caster(gi::bake_input_from(scene)).value();
  gi::VplSet vpls;
  vpls.position = {glm::vec3(0.0f)};
  vpls.normal = {glm::vec3(0, 1, 0)};
  vpls.area_m2 = {1.0f};
  const std::vector<glm::vec3> two(2, glm::vec3(1.0f));
  EXPECT_FALSE(gi::bake_world_probes(*caster, vpls, two, {}).ok());
  const std::vector<glm::vec3> nan_power{glm::vec3(NAN)};
  EXPECT_FALSE(gi::bake_world_probes(*caster, vpls, nan_power, {}).ok());
  const std::vector<glm::vec3> one{glm::vec3(1.0f)};
  EXPECT_FALSE(gi::bake_world_probes(*caster, vpls, one, {.spacing_m = 0.0f}).ok());
}

}  // namespace

// Two VPLs 2e9 m apart: the spacing widens until the grid fits (it overflowed the int
// dimensions and threw std::length_error).
TEST(BrfWorldProbes, FarApartVplsWidenTheSpacingInsteadOfOverflowing) {
  const engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, 0.6f, {0.3f, 0.4f, -0.2f}, 4.0f));
  auto caster = gi::make_static_caster(gi::bake_input_from(scene)).value();
  gi::VplSet vpls;
  for (float x : {-1e9f, 1e9f}) {
    vpls.position.push_back({x, 0.0f, 0.0f});
    vpls.normal.push_back({0.0f, 1.0f, 0.0f});
    vpls.albedo.push_back(glm::vec3(0.5f));
    vpls.area_m2.push_back(1.0f);
  }
  vpls.sample_first = {0, 0, 0};
  const std::vector<glm::vec3> power(2, glm::vec3(1.0f));
  auto grid = gi::bake_world_probes(*caster, vpls, power, {.spacing_m = 1.0f, .max_probes = 4096, .threads = 1});
  ASSERT_TRUE(grid) << grid.error().to_string();
  EXPECT_LE(grid->probe_count(), 4096u);
  EXPECT_GT(grid->spacing, 1e5f);
}

// A damaged field whose inner radius is subnormal: every lookup stays finite and in range
// (the sphere index was NaN, then INT_MIN: a read far outside the coefficients).
TEST(BrfRadianceField, DegenerateRadiiLookupsStayInRange) {
  gi::BasisRadianceField f;
  f.spheres = 3;
  f.face_resolution = 2;
  f.sh_bands = 1;
  f.basis_count = 1;
  f.inner_radius = 1e-38f;
  f.outer_radius = 3e38f;
  f.coefficients.assign(static_cast<std::size_t>(f.spheres) * 6 * 2 * 2, 1.0f);
  std::vector<float> out(1, -1.0f);
  for (glm::vec3 p : {glm::vec3(1, 0, 0), glm::vec3(1e20f, 0, 0), glm::vec3(1e-30f, 0, 0)}) {
    f.sample(p, out);
    EXPECT_TRUE(std::isfinite(out[0])) << p.x;
  }
}
