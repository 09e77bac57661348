// One definition of direct and indirect light (docs/light_atlas.md, "Direct and indirect
// light"): direct is the light that arrives straight from an emitter, the sun and the sky
// included, shadowed; indirect is the light that reflected off at least one surface. The
// light atlas's gather (its parts: `direct` + `baked_direct`, `indirect`) and the path
// tracer's atlas output (gi-reference --atlas-out: atlas_direct, atlas_indirect) must split
// a texel's light the same way, per texel, under a sky and a sun.
#include <gtest/gtest.h>
#include <engine/scene_asset.h>
#include <engine/sun.h>
#include <gi/bake_input.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/texel_gather.h"
#include "light_atlas/texel_landing.h"
#include "raytrace/atlas_reference.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace {

// A floor 4 x 4 m facing up and a wall 4 m wide, 3 m high standing on its -x edge, facing +x
// (an open box of two sides) under a gradient sky and a sun. The wall's shading normals lean
// `lean_rad` up at its top and down at its foot (a smoothed surface: its texels' normals are
// off its face), the floor's are flat.
gi::BakeInput wall_and_floor_under_the_sky(float lean_rad, glm::vec3 sun_direction = {-0.6f, -1.0f, 0.3f}) {
  engine::SceneAsset a;
  engine::Primitive floor, wall;
  floor.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  floor.normals.assign(4, glm::vec3(0, 1, 0));
  floor.indices = {0, 3, 2, 0, 2, 1};
  wall.positions = {{-2, 0, -2}, {-2, 0, 2}, {-2, 3, 2}, {-2, 3, -2}};
  const glm::vec3 up(std::cos(lean_rad), std::sin(lean_rad), 0.0f), down(std::cos(lean_rad), -std::sin(lean_rad), 0.0f);
  wall.normals = {down, down, up, up};
  wall.indices = {0, 2, 1, 0, 3, 2};  // faces +x
  engine::Material grey;
  grey.base_color = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  a.materials.push_back(grey);
  floor.material = wall.material = 0;
  a.meshes.push_back({.name = "floor", .primitives = {floor}});
  a.meshes.push_back({.name = "wall", .primitives = {wall}});
  for (int m = 0; m < 2; ++m) {
    engine::Node n;
    n.name = a.meshes[static_cast<std::size_t>(m)].name;
    n.mesh = m;
    n.gi.mobility = engine::Mobility::Static;
    a.nodes.push_back(n);
  }
  a.environment.sky_gradient = {.zenith = {10, 16, 30}, .horizon = {28, 30, 34}, .ground = {6, 6, 6}};
  engine::set_sun(a, {.direction = sun_direction, .irradiance = {700.0f, 650.0f, 600.0f}});
  return gi::bake_input_from(a);
}

// Per texel, the gather's parts against the path tracer's at the same texel: the worst
// difference of each part in units of the texel's total irradiance (at least 5% of the mean
// total), beyond (for indirect) four standard deviations of the path tracer's noise, and the
// mean difference of the indirect part relative to the mean total.
struct Split {
  double worst_direct = 0.0, worst_indirect = 0.0, indirect_bias = 0.0;
  std::size_t texels = 0;
};

// `facing`: the texels compared, all, the horizontal ones (|normal.y| above 0.9), those
// facing down (normal.y below -0.9) or the vertical ones (|normal.y| below 0.1).
enum class Facing { All, Horizontal, Down, Vertical };

// `near_rays`, `near_depth`: TexelGatherSettings::near_regather_rays and near_regather_depth
// (the high preset's 0 and 1 unless given).
Split compare_split(const gi::BakeInput& input, Facing facing = Facing::All, int near_rays = 0,
                    float texels_per_metre = 4.0f, int near_depth = 1) {
  gi::LightAtlasSettings s = gi::light_atlas_preset("high").value();
  s.texels_per_metre = texels_per_metre;
  auto layout = gi::static_world_layout(input, s.texels_per_metre);
  EXPECT_TRUE(layout);
  auto scene = gi::prepare_static_scene(input, *layout, gi::BakeLights::Static, gi::texel_placement(s));
  EXPECT_TRUE(scene) << scene.error().to_string();
  gi::ThreadPool pool(2);
  gi::TexelGatherSettings g = s.gather;
  g.gather_rays = 4096;
  g.near_regather_rays = near_rays;
  g.near_regather_depth = near_depth;
  auto gathered = gi::gather_atlas(*scene, *layout, g, pool);
  EXPECT_TRUE(gathered) << gathered.error().to_string();
  auto truth = gi::reference_atlas_irradiance(input, scene->texels,
                                              {.samples_per_pixel = 4096, .max_bounces = -1, .seed = 3, .threads = 2});
  EXPECT_TRUE(truth) << truth.error().to_string();
  Split out;
  double bias = 0.0, total = 0.0;
  const auto compared = [&](std::size_t t) {
    const float ny = scene->texels.normal[t].y;
    return scene->texels.valid[t] && !(facing == Facing::Horizontal && std::fabs(ny) < 0.9f) &&
           !(facing == Facing::Down && ny > -0.9f) && !(facing == Facing::Vertical && std::fabs(ny) > 0.1f);
  };
  for (std::size_t t = 0; t < scene->texels.valid.size(); ++t)
    if (compared(t)) total += static_cast<double>(truth->direct[t].y + truth->indirect[t].y), ++out.texels;
  const double floor = 0.05 * total / static_cast<double>(out.texels);  // dark texels: 5% of the mean total
  for (std::size_t t = 0; t < scene->texels.valid.size(); ++t) {
    if (!compared(t)) continue;
    const double a_d = static_cast<double>(gathered->direct[t].y + gathered->baked_direct[t].y);
    const double a_i = static_cast<double>(gathered->indirect[t].y);
    const double r_d = static_cast<double>(truth->direct[t].y), r_i = static_cast<double>(truth->indirect[t].y);
    const double sigma = std::sqrt(static_cast<double>(truth->indirect_variance[t].y)),
                 scale = std::max(r_d + r_i, floor);
    out.worst_direct = std::max(out.worst_direct, std::fabs(a_d - r_d) / scale);
    out.worst_indirect = std::max(out.worst_indirect, std::max(0.0, std::fabs(a_i - r_i) - 4.0 * sigma) / scale);
    bias += a_i - r_i;
  }
  out.indirect_bias = bias / total;
  return out;
}

// A sunlit floor 4 x 4 m and on it a slab 2 x 0.2 x 2 m whose underside hangs `gap_m` above
// the floor (a level's stacked geometry: Dabrovic Sponza's gallery floor 2 mm under a
// ceiling slab), under the sky and a sun: the floor under the slab and the slab's underside
// face each other across the gap.
gi::BakeInput slab_over_a_floor(float gap_m) {
  engine::SceneAsset a;
  engine::Primitive floor, slab;
  floor.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  floor.indices = {0, 3, 2, 0, 2, 1};
  const float lo = gap_m, hi = gap_m + 0.2f;
  const auto quad = [&](glm::vec3 c, glm::vec3 u, glm::vec3 v) {
    const auto base = static_cast<std::uint32_t>(slab.positions.size());
    slab.positions.insert(slab.positions.end(), {c, c + u, c + u + v, c + v});
    slab.indices.insert(slab.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  };
  quad({-1.03f, lo, -1.03f}, {2, 0, 0}, {0, 0, 2});     // underside, faces -y
  quad({-1.03f, hi, -1.03f}, {0, 0, 2}, {2, 0, 0});     // top, +y
  quad({-1.03f, lo, -1.03f}, {0, 0, 2}, {0, 0.2f, 0});  // x-, faces -x
  quad({0.97f, lo, -1.03f}, {0, 0.2f, 0}, {0, 0, 2});   // x+, +x
  quad({-1.03f, lo, -1.03f}, {0, 0.2f, 0}, {2, 0, 0});  // z-, -z
  quad({-1.03f, lo, 0.97f}, {2, 0, 0}, {0, 0.2f, 0});   // z+, +z
  engine::Material grey;
  grey.base_color = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  a.materials.push_back(grey);
  floor.material = slab.material = 0;
  a.meshes.push_back({.name = "floor", .primitives = {floor}});
  a.meshes.push_back({.name = "slab", .primitives = {slab}});
  for (int m = 0; m < 2; ++m) {
    engine::Node n;
    n.name = a.meshes[static_cast<std::size_t>(m)].name;
    n.mesh = m;
    n.gi.mobility = engine::Mobility::Static;
    a.nodes.push_back(n);
  }
  a.environment.sky_gradient = {.zenith = {10, 16, 30}, .horizon = {28, 30, 34}, .ground = {6, 6, 6}};
  engine::set_sun(a, {.direction = {0.25f, -1.0f, 0.15f}, .irradiance = {700.0f, 650.0f, 600.0f}});
  return gi::bake_input_from(a);
}

// A sunlit floor 4 x 4 m, a plate 2 x 2 m facing down `gap_m` above it, and a wall 1 m high
// facing +x standing where the plate ends (x = 1), the sun behind the plate's side of it
// (Dabrovic Sponza's gallery: slabs that end at a wall, millimetres over the floor). The
// plate's texels within a texel of the wall see the wall's back face along the plate, and
// relocate_texel_samples moves their samples through it, off the plate, into the open.
gi::BakeInput plate_ending_at_a_wall(float gap_m) {
  engine::SceneAsset a;
  engine::Primitive floor, plate, wall;
  floor.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  floor.indices = {0, 3, 2, 0, 2, 1};
  plate.positions = {{-1, gap_m, -1}, {1, gap_m, -1}, {1, gap_m, 1}, {-1, gap_m, 1}};
  plate.indices = {0, 1, 2, 0, 2, 3};  // faces -y
  wall.positions = {{1, 0, -1.5f}, {1, 0, 1.5f}, {1, 1, 1.5f}, {1, 1, -1.5f}};
  wall.indices = {0, 2, 1, 0, 3, 2};  // faces +x
  engine::Material grey;
  grey.base_color = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  a.materials.push_back(grey);
  floor.material = plate.material = wall.material = 0;
  a.meshes.push_back({.name = "floor", .primitives = {floor}});
  a.meshes.push_back({.name = "plate", .primitives = {plate}});
  a.meshes.push_back({.name = "wall", .primitives = {wall}});
  for (int m = 0; m < 3; ++m) {
    engine::Node n;
    n.name = a.meshes[static_cast<std::size_t>(m)].name;
    n.mesh = m;
    n.gi.mobility = engine::Mobility::Static;
    a.nodes.push_back(n);
  }
  a.environment.sky_gradient = {.zenith = {10, 16, 30}, .horizon = {28, 30, 34}, .ground = {6, 6, 6}};
  engine::set_sun(a, {.direction = {-0.25f, -1.0f, 0.15f}, .irradiance = {700.0f, 650.0f, 600.0f}});
  return gi::bake_input_from(a);
}

}  // namespace

// The wall's texels see nothing but the sky, the sun and the floor: their indirect light is
// what the floor reflects, whatever their shading normals. Before the path tracer's receiver
// took its surface's own plane (SurfacePoint::face_normal), a texel whose normal leaned off
// its face sent some of its rays below that plane into the front of its own wall and counted
// the wall's light as indirect: measured on the leaning wall, the worst texel's indirect
// 2.7% of its total beyond the noise, the mean 0.31% of the mean total above the gather's;
// now 0 and 0.07% (flat normals: 0 and 0.02%).
TEST(DirectIndirectSplit, GatherAndPathTracerSplitTheSameWayUnderASkyAndASun) {
  for (const float lean_deg : {0.0f, 30.0f}) {
    const Split s = compare_split(wall_and_floor_under_the_sky(lean_deg * std::numbers::pi_v<float> / 180.0f));
    std::printf(
        "wall leaning %.0f deg, %zu texels: worst direct %.4f, worst indirect beyond 4 sigma %.4f (of the texel's "
        "total), indirect bias %+.4f (of the mean total)\n",
        static_cast<double>(lean_deg), s.texels, s.worst_direct, s.worst_indirect, s.indirect_bias);
    EXPECT_LT(s.worst_direct, 0.01) << lean_deg << " deg";
    EXPECT_LT(s.worst_indirect, 0.01) << lean_deg << " deg";
    EXPECT_LT(std::fabs(s.indirect_bias), 0.002) << lean_deg << " deg";
  }
}

// Light from below a receiver's own face is dark for the sun too. The gather's direct_at
// always dropped it; the path tracer's receiver dropped its rays below the face but its
// next-event estimate of the sun did not. On a closed surface the surface itself shadows
// such a sun; where it does not (Dabrovic Sponza's roof edges, texels whose normals lean 60
// degrees off their face) the path tracer lit texels at 415 W/m^2 that the gather left at 3,
// most of the direct part's 2.1% error on the whole lightmap. Here a receiver in the open
// 2 m above the floor, its normal leaning 60 degrees up off a face towards +x, the sun 17
// degrees behind that face: only the sky's light from above the face reaches it, less than
// the same receiver gets with its face along its normal, by at least the sun's share.
TEST(DirectIndirectSplit, TheSunBehindAReceiversFaceIsDark) {
  const glm::vec3 to_sun = glm::normalize(glm::vec3(-0.3f, 0.95f, 0.0f));
  const gi::BakeInput input = wall_and_floor_under_the_sky(0.0f, -to_sun);
  const glm::vec3 n(0.5f, 0.8660254f, 0.0f);
  const std::vector<gi::SurfacePoint> points = {{.position_m = {0, 2, 0}, .normal = n, .face_normal = {1, 0, 0}},
                                                {.position_m = {0, 2, 0}, .normal = n, .face_normal = n}};
  auto e = gi::reference_irradiance(input, points, {.samples_per_pixel = 1024, .max_bounces = 0, .seed = 5});
  ASSERT_TRUE(e) << e.error().to_string();
  const double sun = 650.0 * static_cast<double>(glm::dot(n, to_sun));
  const double behind = static_cast<double>(e->direct[0].y), in_front = static_cast<double>(e->direct[1].y);
  std::printf("direct behind the face %.1f, in front %.1f, the sun's share %.1f W/m^2\n", behind, in_front, sun);
  EXPECT_GT(in_front - behind, 0.95 * sun);
}

// The slab's underside 2 mm above the sunlit floor: no light enters the gap, and the path
// tracer finds its texels nearly dark (6 W/m^2). The gather's rays from them land on the
// floor 2 mm away and used to read the floor's texel there, whose sample lies in the sun
// when the texel straddles the slab's rim: measured at 4 texels/m, the worst texel's
// indirect 15.7 times the mean total's 5% above the path tracer's. Surfaces facing each
// other closer than kGapTexels now read dark: 0.15, on the floor beside the slab. The
// horizontal texels only: the slab's sides, one texel tall, read 18% too dark on average,
// another cause (docs/light_atlas.md, "Noise against floor, cause by cause").
TEST(DirectIndirectSplit, AGapBetweenStackedSurfacesStaysDark) {
  const Split s = compare_split(slab_over_a_floor(0.002f), Facing::Horizontal);
  std::printf(
      "slab 2 mm over a floor, %zu horizontal texels: worst direct %.4f, worst indirect beyond 4 sigma %.4f, "
      "indirect bias %+.4f\n",
      s.texels, s.worst_direct, s.worst_indirect, s.indirect_bias);
  EXPECT_LT(s.worst_indirect, 0.25);
  EXPECT_LT(std::fabs(s.indirect_bias), 0.005);
}

// Issue 35's floor, cause 1a: a plate's texel whose sample relocate_texel_samples moved
// through the wall at the plate's end lies in the open, 1.5 mm over the sunlit floor beyond
// the wall, and the path tracer finds the floor's light there. The gap rule (a surface facing
// the texel closer than kGapTexels encloses a dark gap) darkened every ray of it: the texels
// read about nothing. The rule now asks whether something covers the landing point. Measured:
// the worst texel's indirect 0.81 of its total beyond the noise, the bias -0.78 of the mean
// total; now 0.28 and -0.16 (the moved texels read 360 W/m^2 against the path tracer's 415,
// the texels along the plate's open rims half their 20 W/m^2).
TEST(AtlasFloor, ASampleMovedOffItsSurfaceIsNotInAGap) {
  const Split s = compare_split(plate_ending_at_a_wall(0.004f), Facing::Down);
  std::printf(
      "plate 4 mm over a floor, ending at a wall, %zu downward texels: worst direct %.4f, worst indirect beyond 4 "
      "sigma %.4f, indirect bias %+.4f\n",
      s.texels, s.worst_direct, s.worst_indirect, s.indirect_bias);
  EXPECT_LT(s.worst_indirect, 0.4);
  EXPECT_LT(std::fabs(s.indirect_bias), 0.25);
}

// Issue 35's floor, cause 1b: a slab 5 cm over a sunlit floor (a fifth of a texel). The floor's
// texels straddling the slot's mouth hold the light of their sample, in the sun or in the
// slot's shade, and the slab's underside read it bilinearly where its rays land in the dark
// slot. The read now takes the lights' direct light at the landing point wherever a shadow
// edge crosses the landing texel's neighbourhood. Measured: the worst texel 0.64, the bias
// -0.53 (too dark: the bilinear read spread the floor's texels inside the slot, dark at
// their samples, over the sunlit floor at its mouth, where most of its light comes from);
// now 0.085 and -0.085.
TEST(AtlasFloor, ASlotUnderASlabReadsItsOwnShade) {
  const Split s = compare_split(slab_over_a_floor(0.05f), Facing::Down);
  std::printf(
      "slab 5 cm over a floor, %zu downward texels: worst direct %.4f, worst indirect beyond 4 sigma %.4f, "
      "indirect bias %+.4f\n",
      s.texels, s.worst_direct, s.worst_indirect, s.indirect_bias);
  EXPECT_LT(s.worst_indirect, 0.15);
  EXPECT_LT(std::fabs(s.indirect_bias), 0.12);
}

// Issue 35's floor, near landings: a ray from the slab's 20 cm sides lands on the floor a few
// centimetres from the slab's foot, where the floor's texel (17 cm at 6 texels/m) holds the
// light of its sample, up to a texel out. The sky and the indirect light at the foot are not
// the sample's (the slab hides half the sky there and lights it from its sunlit side), so a
// landing nearer than a texel takes them at the landing point itself, from a few rays of its
// own (near_regather_rays). Measured on the sides: the worst texel 0.056 -> 0.017, the bias
// -3.0% -> -1.6% of their light (4096 gather rays, against 4096 spp).
TEST(AtlasFloor, NearLandingsBesideASlabTakeTheLightOfTheirPoint) {
  const gi::BakeInput input = slab_over_a_floor(0.002f);
  const Split before = compare_split(input, Facing::Vertical, 0, 6.0f);
  const Split after = compare_split(input, Facing::Vertical, 4, 6.0f);
  std::printf(
      "slab 2 mm over a floor at 6 texels/m, %zu side texels: worst indirect beyond 4 sigma %.4f -> %.4f, indirect "
      "bias %+.4f -> %+.4f (reads at the texels -> regathered at near landings)\n",
      after.texels, before.worst_indirect, after.worst_indirect, before.indirect_bias, after.indirect_bias);
  EXPECT_LT(after.worst_indirect, 0.03);
  EXPECT_LT(std::fabs(after.indirect_bias), 0.022);
}

// Issue 35's floor, near landings in a corner: a regather from the floor at the slab's foot
// (the previous test) lands on the slab's side again, nearer than a texel, where the side's
// texel (17 cm at 6 texels/m, the side 20 cm tall) holds the light of its sample, not of the
// point. A second level of regathers takes the light at that point too (near_regather_depth 2).
// Measured on the sides: the worst texel 0.0166 -> 0.0000 beyond the noise, the bias -1.60% ->
// -0.97% of their light.
TEST(AtlasFloor, RegathersInACornerTakeTheSecondNearBounceAtItsPoint) {
  const gi::BakeInput input = slab_over_a_floor(0.002f);
  const Split one = compare_split(input, Facing::Vertical, 4, 6.0f, 1);
  const Split two = compare_split(input, Facing::Vertical, 4, 6.0f, 2);
  std::printf(
      "slab 2 mm over a floor at 6 texels/m, %zu side texels: worst indirect beyond 4 sigma %.4f -> %.4f, indirect "
      "bias %+.4f -> %+.4f (one level of regathers -> two)\n",
      two.texels, one.worst_indirect, two.worst_indirect, one.indirect_bias, two.indirect_bias);
  EXPECT_LT(two.worst_indirect, 0.008);
  EXPECT_LT(std::fabs(two.indirect_bias), 0.013);
}

// Issue 35's floor, vertex normals opposite their face: Dabrovic Sponza's column bases have
// ledges whose vertex normals point into the stone, and a near landing there turned such a
// normal over (the rule for the back of a double-sided surface), leaning it 50 degrees off
// the ledge: the sun read there was a third of what the path tracer, which shades a normal
// below the surface with the face's own, finds. Measured on Sponza at 8 texels/m (the
// breakdown tool, medium, 2 x 64 spp): indirect-dominated texels 6.46% -> 5.46%, the
// whole lightmap 1.44% -> 1.31%. The rule is the path tracer's (gi::shading_brdf), case
// by case.
TEST(AtlasFloor, ALandingsShadingNormalIsThePathTracers) {
  gi::ShadingTriangle tri;
  tri.p0 = glm::vec3(0.0f);
  tri.e1 = glm::vec3(1, 0, 0);
  tri.e2 = glm::vec3(0, 0, -1);
  tri.face_normal = glm::vec3(0, 1, 0);
  const glm::vec2 middle(1.0f / 3.0f, 1.0f / 3.0f);
  const glm::vec3 up(0, 1, 0), down(0, -1, 0);
  const auto near = [](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-5f; };
  // A normal leaning off the face but above it is kept.
  const glm::vec3 lean = glm::normalize(glm::vec3(0.3f, 1.0f, 0.0f));
  tri.n0 = tri.n1 = tri.n2 = lean;
  EXPECT_TRUE(near(gi::landing_shading_normal(tri, middle, up), lean));
  // Below the face (Sponza's ledge: interpolated (-0.75, -0.62, -0.22)): the face's own, not
  // the normal turned over (0.75, 0.62, 0.22), which leans 51 degrees off the ledge.
  tri.n0 = glm::vec3(-0.08f, -0.99f, -0.10f);
  tri.n1 = glm::normalize(glm::vec3(-0.95f, -0.2f, -0.3f));
  tri.n2 = glm::normalize(glm::vec3(-0.9f, -0.4f, -0.2f));
  const glm::vec3 ledge = gi::landing_shading_normal(tri, middle, up);
  EXPECT_TRUE(near(ledge, up)) << ledge.x << " " << ledge.y << " " << ledge.z;
  // The back of a double-sided surface: the normal turned over to that side.
  tri.n0 = tri.n1 = tri.n2 = lean;
  EXPECT_TRUE(near(gi::landing_shading_normal(tri, middle, down), -lean));
  // ... and the back's face where the turned-over normal points into the surface.
  tri.n0 = tri.n1 = tri.n2 = glm::normalize(glm::vec3(0.2f, -1.0f, 0.0f));
  EXPECT_TRUE(near(gi::landing_shading_normal(tri, middle, down), down));
  // A zero or non-finite interpolated normal: the side.
  tri.n0 = tri.n1 = tri.n2 = glm::vec3(0.0f);
  EXPECT_TRUE(near(gi::landing_shading_normal(tri, middle, up), up));
}
