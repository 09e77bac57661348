// Reflection probes' placement and bake (reflection_probes/reflection_probes.h) on scenes
// with known answers: two rooms give two probes whose boxes are the rooms; a closed room
// whose every surface reflects the same light is the same radiance in every direction and at
// every level; only the probe whose room changed is re-baked.
#include "reflection_probes/reflection_probes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "raytrace/embree_ray_caster.h"
#include "raytrace/scene_adapter.h"
#include "uv/atlas_layout.h"

namespace {

void add_quad(gi::BakePrimitive& p, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const auto base = static_cast<std::uint32_t>(p.positions.size());
  p.positions.insert(p.positions.end(), {c, c + u, c + u + v, c + v});
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

gi::BakeMaterial lambert(float albedo) {
  return gi::BakeMaterial{.base_color = glm::vec3(albedo), .metallic = 0.0f, .roughness = 1.0f, .specular = 0.0f};
}

void add_static(gi::BakeInput& in, gi::BakePrimitive p, const char* name) {
  p.material = 0;
  gi::BakeMesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(std::move(p));
  in.instances.push_back(gi::BakeInstance{.name = name,
                                          .mesh = static_cast<std::uint32_t>(in.meshes.size()),
                                          .id = static_cast<std::int64_t>(in.instances.size())});
  in.meshes.push_back(std::move(mesh));
}

// An inward-facing box [lo, hi] (the six faces as one primitive).
gi::BakePrimitive room(glm::vec3 lo, glm::vec3 hi) {
  gi::BakePrimitive p;
  const glm::vec3 s = hi - lo;
  add_quad(p, lo, {0, 0, s.z}, {s.x, 0, 0});                  // floor, +y
  add_quad(p, {lo.x, hi.y, lo.z}, {s.x, 0, 0}, {0, 0, s.z});  // ceiling, -y
  add_quad(p, lo, {s.x, 0, 0}, {0, s.y, 0});                  // z = lo, +z
  add_quad(p, {lo.x, lo.y, hi.z}, {0, s.y, 0}, {s.x, 0, 0});  // z = hi, -z
  add_quad(p, lo, {0, s.y, 0}, {0, 0, s.z});                  // x = lo, +x
  add_quad(p, {hi.x, lo.y, lo.z}, {0, 0, s.z}, {0, s.y, 0});  // x = hi, -x
  return p;
}

// Two 4 x 3 x 4 m rooms side by side along x, joined by a 1 x 2 m doorway in the shared wall
// (two walls back to back, 0.2 m apart, with the doorway's reveal between them).
gi::BakeInput two_rooms() {
  gi::BakeInput in;
  in.name = "two rooms";
  in.materials.push_back(lambert(0.5f));
  gi::BakePrimitive a, b;
  // Room A [0, 4] x [0, 3] x [0, 4]; room B [4.2, 8.2] x ... ; doorway z in [1.5, 2.5], y in [0, 2].
  const auto rooms_walls = [](gi::BakePrimitive& p, float x0, float x1, bool door_at_x1) {
    add_quad(p, {x0, 0, 0}, {0, 0, 4}, {x1 - x0, 0, 0});  // floor
    add_quad(p, {x0, 3, 0}, {x1 - x0, 0, 0}, {0, 0, 4});  // ceiling
    add_quad(p, {x0, 0, 0}, {x1 - x0, 0, 0}, {0, 3, 0});  // z = 0
    add_quad(p, {x0, 0, 4}, {0, 3, 0}, {x1 - x0, 0, 0});  // z = 4
    const float wx = door_at_x1 ? x1 : x0;
    const float sign = door_at_x1 ? -1.0f : 1.0f;  // the wall faces into the room
    // The wall at wx with a doorway z in [1.5, 2.5], y in [0, 2]: three quads around the door.
    const auto wall = [&](glm::vec3 c, glm::vec3 u, glm::vec3 v) {
      if (sign > 0)
        add_quad(p, c, v, u);
      else
        add_quad(p, c, u, v);
    };
    wall({wx, 0, 0}, {0, 0, 1.5f}, {0, 3, 0});
    wall({wx, 0, 2.5f}, {0, 0, 1.5f}, {0, 3, 0});
    wall({wx, 2, 1.5f}, {0, 0, 1.0f}, {0, 1, 0});
    // The far wall, solid.
    const float fx = door_at_x1 ? x0 : x1;
    if (door_at_x1)
      add_quad(p, {fx, 0, 0}, {0, 3, 0}, {0, 0, 4});
    else
      add_quad(p, {fx, 0, 0}, {0, 0, 4}, {0, 3, 0});
  };
  rooms_walls(a, 0.0f, 4.0f, true);
  rooms_walls(b, 4.2f, 8.2f, false);
  add_static(in, std::move(a), "room a");
  add_static(in, std::move(b), "room b");
  return in;
}

TEST(ReflectionProbePlacement, TwoRoomsGiveTwoProbesWhoseBoxesAreTheRooms) {
  const gi::BakeInput in = two_rooms();
  auto caster = gi::make_embree_ray_caster(gi::rt_scene_from(in));
  ASSERT_TRUE(caster) << caster.error().to_string();
  const auto probes = gi::place_probes(**caster, {0, 0, 0}, {8.2f, 3, 4}, gi::ProbePlacementSettings{});
  ASSERT_EQ(probes.size(), 2u);
  std::vector<gi::ProbeVolume> sorted = probes;
  std::sort(sorted.begin(), sorted.end(), [](const auto& p, const auto& q) { return p.centre.x < q.centre.x; });
  const glm::vec3 rooms[2][2] = {{{0, 0, 0}, {4, 3, 4}}, {{4.2f, 0, 0}, {8.2f, 3, 4}}};
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(glm::length(sorted[i].box_min - rooms[i][0]), 0.0f, 1e-3f) << "probe " << i;
    EXPECT_NEAR(glm::length(sorted[i].box_max - rooms[i][1]), 0.0f, 1e-3f) << "probe " << i;
    EXPECT_NEAR(glm::length(sorted[i].centre - 0.5f * (rooms[i][0] + rooms[i][1])), 0.0f, 1e-3f) << "probe " << i;
  }
}

// The demo level's plan: a hub, a 2 m wide corridor and a side room, the world 14.4 m wide,
// so the 4 m grid's candidates (x = 1.6, 5.2, 8.8, 12.4) all miss the corridor (x in [3, 5]).
// The half-size second pass gives it its own probe, whose box is the corridor.
TEST(ReflectionProbePlacement, ANarrowCorridorBetweenTheGridsCandidatesGetsAProbe) {
  gi::BakeInput in;
  in.name = "hub and corridor";
  in.materials.push_back(lambert(0.5f));
  add_static(in, room({0, 0, 0}, {8.2f, 3, 8.2f}), "hub");
  add_static(in, room({3, 0, 8.4f}, {5, 3, 16.4f}), "corridor");
  add_static(in, room({8.4f, 0, 1}, {14.2f, 3, 7}), "side room");
  auto caster = gi::make_embree_ray_caster(gi::rt_scene_from(in));
  ASSERT_TRUE(caster) << caster.error().to_string();
  const auto probes = gi::place_probes(**caster, {-0.2f, 0, -0.2f}, {14.2f, 3, 16.4f}, gi::ProbePlacementSettings{});
  ASSERT_EQ(probes.size(), 3u);
  const auto corridor = std::find_if(probes.begin(), probes.end(), [](const gi::ProbeVolume& v) {
    return v.contains({4.0f, 1.5f, 12.0f});
  });
  ASSERT_NE(corridor, probes.end());
  EXPECT_NEAR(glm::length(corridor->box_min - glm::vec3(3, 0, 8.4f)), 0.0f, 1e-3f);
  EXPECT_NEAR(glm::length(corridor->box_max - glm::vec3(5, 3, 16.4f)), 0.0f, 1e-3f);
}

// With corridor_aspect 2 the same corridor (8 m long, 2 m wide) becomes 4 segments of 2 m, a
// probe at each one's centre, each box reaching kProbeFadeM / 2 into the next; the blend's
// weights are equal on the plane between two segments and fade to (almost) nothing at the far
// end of their overlap, and the sides all of them share (the floor) cancel.
TEST(ReflectionProbePlacement, ACorridorCutIntoSegmentsFadesFromOneProbeToTheNext) {
  gi::BakeInput in;
  in.name = "hub and corridor";
  in.materials.push_back(lambert(0.5f));
  add_static(in, room({0, 0, 0}, {8.2f, 3, 8.2f}), "hub");
  add_static(in, room({3, 0, 8.4f}, {5, 3, 16.4f}), "corridor");
  auto caster = gi::make_embree_ray_caster(gi::rt_scene_from(in));
  ASSERT_TRUE(caster) << caster.error().to_string();
  gi::ProbePlacementSettings settings;
  settings.corridor_aspect = 2.0f;
  auto probes = gi::place_probes(**caster, {-0.2f, 0, -0.2f}, {8.4f, 3, 16.4f}, settings);
  std::erase_if(probes, [](const gi::ProbeVolume& v) { return v.box_min.z < 8.0f; });  // the hub's
  ASSERT_EQ(probes.size(), 4u);
  std::sort(probes.begin(), probes.end(), [](const auto& p, const auto& q) { return p.centre.z < q.centre.z; });
  const float half_fade = 0.5f * gi::kProbeFadeM;
  for (int k = 0; k < 4; ++k) {
    const gi::ProbeVolume& v = probes[static_cast<std::size_t>(k)];
    const float z0 = 8.4f + 2.0f * static_cast<float>(k), z1 = z0 + 2.0f;
    EXPECT_NEAR(glm::length(v.centre - glm::vec3(4.0f, 1.5f, z0 + 1.0f)), 0.0f, 1e-3f) << "segment " << k;
    EXPECT_NEAR(v.box_min.z, k > 0 ? z0 - half_fade : z0, 1e-3f) << "segment " << k;
    EXPECT_NEAR(v.box_max.z, k < 3 ? z1 + half_fade : z1, 1e-3f) << "segment " << k;
    EXPECT_NEAR(v.box_min.x, 3.0f, 1e-3f);
    EXPECT_NEAR(v.box_max.x, 5.0f, 1e-3f);
  }
  const auto ratio = [&](glm::vec3 p) {
    return gi::probe_blend_weight(probes[2], p, 0.05f) / gi::probe_blend_weight(probes[1], p, 0.05f);
  };
  EXPECT_NEAR(ratio({4.0f, 0.0f, 12.4f}), 1.0f, 1e-4f);  // on the floor, between segments 1 and 2
  EXPECT_NEAR(ratio({3.1f, 1.0f, 12.4f}), 1.0f, 1e-4f);  // near a wall
  EXPECT_LT(ratio({4.0f, 0.0f, 12.4f - half_fade + 0.01f}), 0.05f);
  EXPECT_GT(ratio({4.0f, 0.0f, 12.4f + half_fade - 0.01f}), 20.0f);
  EXPECT_EQ(gi::probe_blend_weight(probes[2], {4.0f, 0.0f, 11.0f}, 0.05f), 0.0f);
}

// An outward-facing box [lo, hi] (a block standing in a room).
gi::BakePrimitive block(glm::vec3 lo, glm::vec3 hi) {
  gi::BakePrimitive p;
  const glm::vec3 s = hi - lo;
  add_quad(p, lo, {s.x, 0, 0}, {0, 0, s.z});                  // bottom, -y
  add_quad(p, {lo.x, hi.y, lo.z}, {0, 0, s.z}, {s.x, 0, 0});  // top, +y
  add_quad(p, lo, {0, s.y, 0}, {s.x, 0, 0});                  // z = lo, -z
  add_quad(p, {lo.x, lo.y, hi.z}, {s.x, 0, 0}, {0, s.y, 0});  // z = hi, +z
  add_quad(p, lo, {0, 0, s.z}, {0, s.y, 0});                  // x = lo, -x
  add_quad(p, {hi.x, lo.y, lo.z}, {0, s.y, 0}, {0, 0, s.z});  // x = hi, +x
  return p;
}

// glossy_room's plan: an 8 x 3 x 5 m room and, when `blocks`, a 3.4 m long, 1.4 m high row of
// blocks at z 0.4-1.5 m, between the room's centre and its +z wall.
gi::BakeInput room_with_blocks(bool blocks) {
  gi::BakeInput in;
  in.name = blocks ? "room with blocks" : "empty room";
  in.materials.push_back(lambert(0.5f));
  add_static(in, room({-4, 0, -2.5f}, {4, 3, 2.5f}), "room");
  if (blocks) add_static(in, block({-1.6f, 0, 0.4f}, {1.8f, 1.4f, 1.5f}), "blocks");
  return in;
}

// The probe at the room's centre, 1.5 m up, does not see the floor behind the blocks (about an
// eighth of the floor): a second probe with the same box is captured over it, 0.8 m up; the
// same room without the blocks gets one probe.
TEST(ReflectionProbePlacement, AFloorHiddenBehindBlocksGetsASecondViewpointOverIt) {
  for (const bool blocks : {false, true}) {
    const gi::BakeInput in = room_with_blocks(blocks);
    auto caster = gi::make_embree_ray_caster(gi::rt_scene_from(in));
    ASSERT_TRUE(caster) << caster.error().to_string();
    const gi::ProbePlacementSettings settings;
    const auto probes = gi::place_probes(**caster, {-4, 0, -2.5f}, {4, 3, 2.5f}, settings);
    ASSERT_GE(probes.size(), 1u);
    const gi::ProbeVolume& first = probes[0];
    EXPECT_NEAR(glm::length(first.centre - glm::vec3(0, 1.5f, 0)), 0.0f, 1e-3f);
    const gi::HiddenReceivers h = gi::hidden_receivers(**caster, first, settings.receiver_step_m);
    std::printf("%s: %d receiver samples, %d hidden from the probe (share %.3f, centroid %.2f %.2f %.2f)\n",
                in.name.c_str(), h.samples, h.hidden, static_cast<double>(h.share()), static_cast<double>(h.centroid.x),
                static_cast<double>(h.centroid.y), static_cast<double>(h.centroid.z));
    ASSERT_EQ(probes.size(), blocks ? 2u : 1u) << in.name;
    if (!blocks) {
      EXPECT_EQ(h.hidden, 0);
      continue;
    }
    EXPECT_GT(h.share(), settings.second_view_min_share);
    const gi::ProbeVolume& second = probes[1];
    EXPECT_EQ(second.box_min, first.box_min);
    EXPECT_EQ(second.box_max, first.box_max);
    EXPECT_NEAR(second.centre.y, settings.second_view_height, 1e-4f);
    EXPECT_GT(second.centre.z, 1.5f);  // behind the blocks
    EXPECT_LT(second.centre.z, 2.5f);
    EXPECT_LT(std::abs(second.centre.x), 1.6f);
    // From there the floor right behind the blocks is seen.
    const glm::vec3 behind(0.0f, 0.01f, 2.0f);
    const glm::vec3 d = behind - second.centre;
    EXPECT_FALSE((*caster)->occluded(gi::Ray{second.centre, 0.0f, glm::normalize(d), glm::length(d) - 0.02f}));
  }
}

// A closed 3 m room of albedo 0.5 whose atlas holds the same irradiance E everywhere: every
// surface sends E / pi x 0.5 (a Lambertian's directional albedo is its albedo), so the probe
// sees that radiance in every direction, and each prefiltered level keeps it.
TEST(ReflectionProbeBake, UniformlyLitClosedRoomIsUniformAtEveryLevel) {
  gi::BakeInput in;
  in.name = "closed room";
  in.materials.push_back(lambert(0.5f));
  add_static(in, room({-1.5f, 0, -1.5f}, {1.5f, 3, 1.5f}), "room");
  auto layout = gi::static_world_layout(in, 4.0f);
  ASSERT_TRUE(layout) << layout.error().to_string();
  const glm::vec3 e(2.0f, 1.0f, 0.5f);
  const std::vector<glm::vec3> irradiance(static_cast<std::size_t>(layout->width * layout->height), e);
  const gi::ProbeAtlas atlas{&*layout, layout->width, layout->height, irradiance, false};
  gi::ReflectionProbeSettings s;
  s.resolution = 16;
  s.prefilter_samples = 64;
  s.threads = 2;
  auto set = gi::bake_reflection_probes(in, atlas, s);
  ASSERT_TRUE(set) << set.error().to_string();
  ASSERT_EQ(set->probes.size(), 1u);
  const glm::vec3 expected = e / std::numbers::pi_v<float> * 0.5f;
  ASSERT_EQ(set->cubes[0].levels.size(), 5u);
  for (std::size_t m = 0; m < set->cubes[0].levels.size(); ++m)
    for (const glm::vec3& t : set->cubes[0].levels[m]) {
      EXPECT_NEAR(t.x, expected.x, 1e-4f * expected.x) << "level " << m;
      EXPECT_NEAR(t.y, expected.y, 1e-4f * expected.y) << "level " << m;
      EXPECT_NEAR(t.z, expected.z, 1e-4f * expected.z) << "level " << m;
    }
}

// The distances are stored at kProbeDistanceScale x level 0's face size, one per quarter of a
// level-0 texel: with 2 x 2 rays per texel each distance texel is the ray through its own centre,
// the distance from the probe to the closed room's wall along it (the box, analytically). With one
// ray per texel, its four quarters take that ray's distance.
TEST(ReflectionProbeBake, TheDistancesAreOnePerQuarterOfALevel0Texel) {
  gi::BakeInput in;
  in.name = "closed room";
  in.materials.push_back(lambert(0.5f));
  const glm::vec3 lo(-1.5f, 0.0f, -2.0f), hi(2.5f, 3.0f, 1.0f);
  add_static(in, room(lo, hi), "room");
  auto layout = gi::static_world_layout(in, 4.0f);
  ASSERT_TRUE(layout) << layout.error().to_string();
  const std::vector<glm::vec3> irradiance(static_cast<std::size_t>(layout->width * layout->height), glm::vec3(1.0f));
  const gi::ProbeAtlas atlas{&*layout, layout->width, layout->height, irradiance, false};
  gi::ReflectionProbeSettings s;
  s.resolution = 8;
  s.prefilter_samples = 16;
  s.threads = 2;
  for (int supersample : {2, 1}) {
    SCOPED_TRACE(supersample);
    s.supersample = supersample;
    auto set = gi::bake_reflection_probes(in, atlas, s);
    ASSERT_TRUE(set) << set.error().to_string();
    ASSERT_EQ(set->probes.size(), 1u);
    const gi::ProbeCube& c = set->cubes[0];
    const glm::vec3 centre = set->probes[0].centre;
    const int ds = gi::cube_distance_size(c);
    ASSERT_EQ(ds, gi::kProbeDistanceScale * s.resolution);
    ASSERT_EQ(c.distance.size(), static_cast<std::size_t>(6 * ds * ds));
    const auto wall = [&](const glm::vec3& d) {  // the box's side along d from the centre
      float t = 1e30f;
      for (int a = 0; a < 3; ++a) {
        if (d[a] > 0.0f) t = std::min(t, (hi[a] - centre[a]) / d[a]);
        if (d[a] < 0.0f) t = std::min(t, (lo[a] - centre[a]) / d[a]);
      }
      return t;
    };
    int off = 0;
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < ds; ++y)
        for (int x = 0; x < ds; ++x) {
          // supersample 2: the quarter's own ray; 1: the level-0 texel's ray.
          const glm::vec3 d = supersample == 2 ? gi::cube_texel_direction(f, x, y, ds)
                                               : gi::cube_texel_direction(f, x / 2, y / 2, s.resolution);
          if (std::abs(c.distance[gi::cube_texel_index(f, x, y, ds)] - wall(d)) > 1e-3f) ++off;
        }
    EXPECT_EQ(off, 0) << "of " << 6 * ds * ds << " distance texels";
  }
}

// The two rooms lit by a 20 W/sr lamp in room A, 2.5 m above its floor, and an atlas of
// 0.1 W/m^2 everywhere at 4 texels/m (not holding the lamp's light).
struct LitTwoRooms {
  gi::BakeInput in;
  gi::AtlasLayout layout;
  std::vector<glm::vec3> irradiance;
  gi::ProbeAtlas atlas() const { return {&layout, layout.width, layout.height, irradiance, false}; }
};

LitTwoRooms lit_two_rooms() {
  LitTwoRooms r;
  r.in = two_rooms();
  gi::BakeLight lamp;
  lamp.name = "lamp";
  lamp.light.type = engine::LightType::Point;
  lamp.light.intensity = 20.0f;
  lamp.light_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(2, 2.5f, 2));
  r.in.lights.push_back(lamp);
  r.layout = gi::static_world_layout(r.in, 4.0f).value();
  r.irradiance.assign(static_cast<std::size_t>(r.layout.width * r.layout.height), glm::vec3(0.1f));
  return r;
}

// The two rooms lit by a lamp in room A: re-baking for a change inside room B redoes probe B
// alone, bit for bit what a whole bake gives it, and leaves probe A untouched.
TEST(ReflectionProbeBake, AChangeInOneRoomRebakesOnlyItsProbe) {
  const LitTwoRooms rooms = lit_two_rooms();
  const gi::BakeInput& in = rooms.in;
  const gi::ProbeAtlas atlas = rooms.atlas();
  gi::ReflectionProbeSettings s;
  s.resolution = 32;
  s.prefilter_samples = 64;
  s.threads = 2;
  auto set = gi::bake_reflection_probes(in, atlas, s);
  ASSERT_TRUE(set) << set.error().to_string();
  ASSERT_EQ(set->probes.size(), 2u);
  const std::size_t b = set->probes[0].centre.x > 4.0f ? 0 : 1;
  gi::ReflectionProbeSet updated = *set;
  for (auto& level : updated.cubes[b].levels) std::fill(level.begin(), level.end(), glm::vec3(-1.0f));
  updated.stats = {};
  auto redone = gi::rebake_probes_touching(in, atlas, updated, {6, 1, 1}, {7, 2, 2});
  ASSERT_TRUE(redone) << redone.error().to_string();
  ASSERT_EQ(*redone, std::vector<std::size_t>{b});
  EXPECT_EQ(updated.cubes[b].levels, set->cubes[b].levels);
  EXPECT_EQ(updated.cubes[1 - b].levels, set->cubes[1 - b].levels);
  // The cost (docs/reflection_probes.md, "Re-bake of a changed room"), 32^2 faces, 2 threads.
  std::printf(
      "whole bake, 2 probes: capture %.3f s, prefilter %.3f s, %llu rays; re-bake of 1: capture %.3f s, "
      "prefilter %.3f s, %llu rays\n",
      set->stats.capture_seconds, set->stats.prefilter_seconds, static_cast<unsigned long long>(set->stats.rays),
      updated.stats.capture_seconds, updated.stats.prefilter_seconds,
      static_cast<unsigned long long>(updated.stats.rays));
}

// The room with blocks, lit by a lamp above its centre: its two viewpoints share the box, so a
// change anywhere in the room re-bakes both, each bit for bit what a whole bake gives it.
TEST(ReflectionProbeBake, AChangeInARoomWithTwoViewpointsRebakesBoth) {
  gi::BakeInput in = room_with_blocks(true);
  gi::BakeLight lamp;
  lamp.name = "lamp";
  lamp.light.type = engine::LightType::Point;
  lamp.light.intensity = 20.0f;
  lamp.light_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0, 2.5f, 0));
  in.lights.push_back(lamp);
  const gi::AtlasLayout layout = gi::static_world_layout(in, 4.0f).value();
  const std::vector<glm::vec3> irradiance(static_cast<std::size_t>(layout.width * layout.height), glm::vec3(0.1f));
  const gi::ProbeAtlas atlas{&layout, layout.width, layout.height, irradiance, false};
  gi::ReflectionProbeSettings s;
  s.resolution = 32;
  s.prefilter_samples = 64;
  s.threads = 2;
  auto set = gi::bake_reflection_probes(in, atlas, s);
  ASSERT_TRUE(set) << set.error().to_string();
  ASSERT_EQ(set->probes.size(), 2u);
  gi::ReflectionProbeSet updated = *set;
  for (gi::ProbeCube& c : updated.cubes)
    for (auto& level : c.levels) std::fill(level.begin(), level.end(), glm::vec3(-1.0f));
  updated.stats = {};
  auto redone = gi::rebake_probes_touching(in, atlas, updated, {2, 0, 2}, {2.5f, 0.5f, 2.4f});
  ASSERT_TRUE(redone) << redone.error().to_string();
  EXPECT_EQ(*redone, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(updated.cubes[0].levels, set->cubes[0].levels);
  EXPECT_EQ(updated.cubes[1].levels, set->cubes[1].levels);
  // The cost (docs/reflection_probes.md, "A second viewpoint where the first is blocked"), 32^2 faces, 2 threads.
  std::printf("room with two viewpoints, re-bake of both: place %.3f s, capture %.3f s, prefilter %.3f s, %llu rays\n",
              set->stats.place_seconds, updated.stats.capture_seconds, updated.stats.prefilter_seconds,
              static_cast<unsigned long long>(updated.stats.rays));
}

// The diagnosis's oracle probes (ProbeCapturer, docs/reflection_probes.md, "Where the corridor's
// error comes from"): a probe captured anywhere by the capturer is, at a placed probe's centre,
// bit for bit the bake's, levels and distances; its single rays are what the capture averages
// (the lamp's direct light where it reaches, the atlas's light everywhere).
TEST(ReflectionProbeBake, TheCapturerAtAProbesCentreIsTheBakesProbe) {
  const LitTwoRooms rooms = lit_two_rooms();
  const gi::BakeInput& in = rooms.in;
  const gi::ProbeAtlas atlas = rooms.atlas();
  gi::ReflectionProbeSettings s;
  s.resolution = 16;
  s.prefilter_samples = 32;
  s.threads = 2;
  auto set = gi::bake_reflection_probes(in, atlas, s);
  ASSERT_TRUE(set) << set.error().to_string();
  auto capturer = gi::ProbeCapturer::make(in, atlas, s);
  ASSERT_TRUE(capturer) << capturer.error().to_string();
  for (std::size_t i = 0; i < set->probes.size(); ++i) {
    const gi::ProbeCube cube = capturer->bake_at(set->probes[i].centre);
    EXPECT_EQ(cube.levels, set->cubes[i].levels) << "probe " << i;
    EXPECT_EQ(cube.distance, set->cubes[i].distance) << "probe " << i;
  }
  // The floor below the lamp: the lamp's direct light (20 / 2.5^2 W/m^2) and the atlas's 0.1,
  // times 0.5 / pi. The other room's ceiling, above the doorway's top, has the atlas's alone.
  const glm::vec3 lit = capturer->radiance({2, 1, 2}, {0, -1, 0});
  EXPECT_NEAR(lit.x, (20.0f / 6.25f + 0.1f) * 0.5f / std::numbers::pi_v<float>, 0.02f);
  const glm::vec3 dark = capturer->radiance({6.2f, 1, 2}, {0, 1, 0});
  EXPECT_NEAR(dark.x, 0.1f * 0.5f / std::numbers::pi_v<float>, 0.002f);
}

}  // namespace
