// The static world as a light source for dynamic objects (gi/src/brf/world_probes.h):
// probe irradiance from the light atlas's VPLs against the path tracer's indirect
// irradiance at free points of a closed box, and probes inside walls not leaking.
#include <gtest/gtest.h>
#include <engine/scene.h>

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
  std::vector<gi::SurfacePoint> points = {{{0.0f, 0.0f, 0.0f}, {0, 1, 0}},
                                          {{0.95f, 0.0f, 0.0f}, {0, 1, 0}},
                                          {{0.95f, 0.0f, 0.0f}, {-1, 0, 0}},
                                          {{0.2f, -0.95f, 0.3f}, {0, 0, 1}}};
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

// The transfer is bake_world_probes with the power factored out: re-projecting the atlas's
// VPL powers gives the baked probes' SH, and re-projecting other powers (a "moving light"
// relighting a few VPLs) gives what baking with those powers gives, with no ray cast.
TEST(BrfWorldProbes, TransferReprojectsWhatBakingWithThePowersGives) {
  const auto& b = box_with_probes();
  auto caster = gi::make_static_caster(gi::bake_input_from(b.scene)).value();
  const gi::VplSet& v = b.atlas.vpls;
  const gi::WorldProbeTransfer t =
      gi::bake_world_probe_transfer(*caster, b.probes, v.position, v.normal, v.area_m2).value();
  std::size_t valid = 0;
  for (std::uint8_t f : b.probes.valid) valid += f;
  std::printf("transfer: %zu probes (%zu valid), %zu VPLs, %zu entries, %.2f MB\n", b.probes.probe_count(), valid,
              v.size(), t.emitter.size(), static_cast<double>(t.bytes()) / 1e6);
  const auto check = [&](const std::vector<glm::vec3>& power, const gi::WorldProbeGrid& baked) {
    const auto sh = gi::reproject_world_probes(t, power).value();
    ASSERT_EQ(sh.size(), baked.probe_count());
    double worst = 0.0, largest = 0.0;
    for (std::size_t k = 0; k < sh.size(); ++k)
      for (std::size_t j = 0; j < 9; ++j) {
        if (baked.valid[k] == 0) continue;
        worst = std::max(worst, double{glm::length(sh[k][j] - baked.radiance_sh[k][j])});
        largest = std::max(largest, double{glm::length(baked.radiance_sh[k][j])});
      }
    EXPECT_GT(largest, 0.0);
    EXPECT_LT(worst, 1e-4 * largest);
  };
  check(b.atlas.vpl_power, b.probes);
  std::vector<glm::vec3> relit(v.size(), glm::vec3(0.0f));
  for (std::size_t i = 0; i < v.size(); i += 7)
    relit[i] = glm::vec3(3.0f, 1.0f, 0.5f) * (1.0f + static_cast<float>(i % 5));
  check(relit, gi::bake_world_probes(*caster, v, relit, {.spacing_m = 0.5f}).value());
  EXPECT_FALSE(gi::reproject_world_probes(t, std::vector<glm::vec3>(v.size() + 1)).ok());
  std::vector<glm::vec3> nan_power(v.size(), glm::vec3(0.0f));
  nan_power[0].x = std::nanf("");
  EXPECT_FALSE(gi::reproject_world_probes(t, nan_power).ok());
  EXPECT_FALSE(gi::bake_world_probe_transfer(*caster, b.probes, v.position, v.normal, std::span<const float>()).ok());
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

// The sky's bounce reaches dynamic objects: under an open uniform sky of radiance L, a
// 20 x 20 m floor of albedo 0.5 reflects about 0.5 L (Lambertian), so a point 1 m above its
// middle facing down gets E = pi x 0.5 L x (the floor's view factor, 0.98) from the world
// probes — which come from the atlas's VPLs, whose direct light now includes the sky. Facing
// up it gets none from the world (the sky itself is the renderer's term, not the probes').
// Without the sky in the VPLs' direct light both are 0.
TEST(BrfWorldProbes, TheSkysBounceOffTheFloorReachesThem) {
  engine::SceneAsset a;
  engine::Primitive p;
  p.positions = {{-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}};
  p.normals.assign(4, glm::vec3(0, 1, 0));
  p.indices = {0, 3, 2, 0, 2, 1};
  p.material = 0;
  a.materials.push_back({.name = "grey", .base_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)});
  // The floor alone: every VPL lies in one plane. (A 0.2 m tile 4 m up used to give the
  // probe grid its height, when a VPL happened to land on it: a build whose random draws
  // differed put none there, and the grid, one probe thick in the floor's plane, lit nothing.)
  a.meshes.push_back({.name = "floor", .primitives = {p}});
  engine::Node n;
  n.name = "floor";
  n.mesh = 0;
  n.gi.mobility = engine::Mobility::Static;
  a.nodes.push_back(n);
  a.environment.sky_radiance = glm::vec3(1.0f);
  const gi::BakeInput input = gi::bake_input_from(a);
  gi::LightAtlasSettings s = gi::light_atlas_preset("preview").value();
  s.texels_per_metre = 2.0f;
  auto atlas = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(atlas) << atlas.error().to_string();
  auto caster = gi::make_static_caster(input);
  ASSERT_TRUE(caster);
  auto probes = gi::bake_world_probes(**caster, atlas->vpls, atlas->vpl_power, {.spacing_m = 1.0f});
  ASSERT_TRUE(probes) << probes.error().to_string();
  glm::dvec3 power(0.0);
  for (const glm::vec3& v : atlas->vpl_power) power += glm::dvec3(v);
  std::printf("%zu VPLs, total power %.2f W; probe grid %d x %d x %d from (%.2f %.2f %.2f)\n", atlas->vpls.size(),
              power.y, probes->dims.x, probes->dims.y, probes->dims.z, double{probes->origin.x},
              double{probes->origin.y}, double{probes->origin.z});
  const glm::vec3 down = probes->irradiance({0.3f, 1.0f, 0.2f}, {0, -1, 0});
  const glm::vec3 up = probes->irradiance({0.3f, 1.0f, 0.2f}, {0, 1, 0});
  const float expected = 3.14159265f * 0.5f * 0.98f;
  std::printf("1 m over the floor under the sky: E facing down %.3f (expected ~%.3f), facing up %.3f\n", double{down.y},
              double{expected}, double{up.y});
  EXPECT_GT(down.y, 0.7f * expected);
  EXPECT_LT(down.y, 1.3f * expected);
  EXPECT_LT(up.y, 0.15f * expected);
}
