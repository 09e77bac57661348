// engine/light_reach.h (where static lights can reach) and the renderer's use of it
// (RenderSettings::light_reach_culling): the grid is conservative at points it did not
// sample, culls what walls hide, and the image with culling equals the image without.
#include <algorithm>
#include <cmath>
#include <random>

#include <engine/light_reach.h>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

// Two triangles of the quad c +- u +- v.
void add_reach_quad(engine::ReachOccluder& o, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  o.triangles.push_back({c - u - v, c + u - v, c + u + v});
  o.triangles.push_back({c - u - v, c + u + v, c - u + v});
}

// A wall at x = 0 over y [0, 3], z [-4, 4] with a doorway z [-0.5, 0.5], y [0, 2].
engine::ReachOccluder wall_with_doorway() {
  engine::ReachOccluder o;
  add_reach_quad(o, {0.0f, 1.5f, -2.25f}, {0, 1.5f, 0}, {0, 0, 1.75f});  // z [-4, -0.5]
  add_reach_quad(o, {0.0f, 1.5f, 2.25f}, {0, 1.5f, 0}, {0, 0, 1.75f});   // z [0.5, 4]
  add_reach_quad(o, {0.0f, 2.5f, 0.0f}, {0, 0.5f, 0}, {0, 0, 0.5f});     // lintel, y [2, 3]
  o.min = {0.0f, 0.0f, -4.0f};
  o.max = {0.0f, 3.0f, 4.0f};
  return o;
}

TEST(LightReach, SegmentTestSeesThroughTheDoorwayOnly) {
  const std::vector<engine::ReachOccluder> occ{wall_with_doorway()};
  EXPECT_FALSE(engine::segment_blocked(occ, {-2, 1, 0}, {2, 1, 0}, 1e-3f));       // through the doorway
  EXPECT_TRUE(engine::segment_blocked(occ, {-2, 1, 2}, {2, 1, 2}, 1e-3f));        // through the wall
  EXPECT_TRUE(engine::segment_blocked(occ, {-2, 2.5f, 0}, {2, 2.5f, 0}, 1e-3f));  // through the lintel
  EXPECT_FALSE(engine::segment_blocked(occ, {-2, 1, 2}, {-1, 1, -2}, 1e-3f));     // beside it
}

TEST(LightReach, ConservativeAtRandomPointsAndCullsBehindTheWall) {
  const std::vector<engine::ReachOccluder> occ{wall_with_doorway()};
  const glm::vec3 light(-2.0f, 2.5f, 0.0f);
  engine::ReachLight point;
  point.position = light;
  const engine::LightReachGrid g =
      engine::build_light_reach_grid(occ, {point}, glm::vec3(-4, 0, -4), glm::vec3(4, 3, 4), 0.5f);
  ASSERT_FALSE(g.empty());
  EXPECT_EQ(g.all, 1);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ux(-4.0f, 4.0f), uy(0.0f, 3.0f);
  int visible = 0, culled = 0;
  for (int i = 0; i < 4000; ++i) {
    const glm::vec3 p(ux(rng), uy(rng), ux(rng));
    const bool sees = !engine::segment_blocked(occ, p, light, 1e-3f);
    visible += sees ? 1 : 0;
    if (sees) {
      ASSERT_EQ(g.at(p) & 1, 1) << "a point that sees the light lost it: " << p.x << ", " << p.y << ", " << p.z;
    } else if (g.at(p) == 0) {
      ++culled;
    }
  }
  // Both cases occur: the room beyond the wall is mostly culled, the light's room is lit.
  EXPECT_GT(visible, 1000);
  EXPECT_GT(culled, 800);
  // A corner of the far room, far from the doorway's beam: no light.
  EXPECT_EQ(g.at({3.5f, 0.2f, 3.5f}), 0);
  // Outside the grid: every light.
  EXPECT_EQ(g.at({40.0f, 0.0f, 0.0f}), 1);
}

TEST(LightReach, AreaLightsReachOnlyTheirEmittingSide) {
  // A 1 x 1 m panel at y = 2 facing down, no occluders: below it lit, above it not.
  engine::ReachLight area;
  area.position = {0.0f, 2.0f, 0.0f};
  area.direction = {0.0f, -1.0f, 0.0f};
  area.half_x = {0.5f, 0.0f, 0.0f};
  area.half_y = {0.0f, 0.0f, 0.5f};
  const engine::LightReachGrid g =
      engine::build_light_reach_grid({}, {area}, glm::vec3(-3, 0, -3), glm::vec3(3, 6, 3), 0.5f);
  EXPECT_EQ(g.at({1.0f, 0.5f, 1.0f}), 1);
  EXPECT_EQ(g.at({0.0f, 4.5f, 0.0f}), 0);
}

// Two rooms split by a wall with a doorway: a point light in one, a ceiling area light in
// the other, a dynamic box in the doorway. With culling, each pixel is shaded with the
// lights its voxel names; the image must equal the one without culling.
TEST(RendererLightReach, SameImageWithAndWithoutCulling) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(0.7f));
  assets.materials.push_back(diffuse_material(0.5f, 0.4f));
  assets.meshes.push_back(plane_mesh(4.0f, 0));
  engine::Mesh wall;
  wall.name = "wall";
  wall.primitives.emplace_back();
  wall.primitives[0].material = 0;
  add_quad(wall.primitives[0], {0.0f, 1.5f, -2.25f}, {0, 0, 1.75f}, {0, 1.5f, 0});
  add_quad(wall.primitives[0], {0.0f, 1.5f, 2.25f}, {0, 0, 1.75f}, {0, 1.5f, 0});
  add_quad(wall.primitives[0], {0.0f, 2.5f, 0.0f}, {0, 0, 0.5f}, {0, 0.5f, 0});
  assets.materials[0].double_sided = true;
  assets.meshes.push_back(wall);
  assets.meshes.push_back(box_mesh(glm::vec3(0.3f), 1));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  add_mesh(reg, 1, glm::mat4(1.0f));
  add_mesh(reg, 2, glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, 0.3f, 0.2f)), false);
  add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 20.0f}, {-2.0f, 2.5f, 0.5f}, {0, 0, 0});
  add_light(reg, engine::Light{.type = engine::LightType::Area, .intensity = 10.0f, .area_size_m = {1.0f, 1.0f}},
            {2.0f, 2.9f, -1.0f}, {2.0f, 0.0f, -1.0f});
  // A moving point light (its reach is recomputed when it moves), first in room B.
  const engine::Entity lamp =
      add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 8.0f, .moves = true},
                {2.5f, 1.5f, 2.5f}, {0, 0, 0});
  const TestCamera cam{{0.0f, 9.0f, 0.5f}, {0.0f, 0.0f, 0.0f}, 0.9f, 128};
  const engine::Entity camera = cam.add_to(reg);

  auto culled = make_renderer(assets, cam.size, 0.0f);
  auto full = make_renderer(assets, cam.size, 0.0f);
  ASSERT_TRUE(culled && full);
  full->settings().light_reach_culling = false;
  for (const glm::vec3 lamp_at : {glm::vec3(2.5f, 1.5f, 2.5f), glm::vec3(-2.5f, 1.0f, -2.5f)}) {
    reg.write<engine::WorldTransform>(lamp).matrix = looking_at(lamp_at, {0, 0, 0});
    culled->render(reg, camera);
    full->render(reg, camera);
    EXPECT_GT(culled->last_light_groups(), 2);  // the rooms get different light sets
    EXPECT_EQ(full->last_light_groups(), 1);
    const engine::ImageRgbaF a = culled->read_hdr();
    const engine::ImageRgbaF b = full->read_hdr();
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    float peak = 0.0f, worst = 0.0f;
    int lit = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
      peak = std::max(peak, b.pixels[i]);
      worst = std::max(worst, std::abs(a.pixels[i] - b.pixels[i]));
      lit += b.pixels[i] > 0.01f ? 1 : 0;
    }
    EXPECT_GT(lit, 1000);
    EXPECT_LE(worst, 1e-4f * peak) << "peak " << peak << ", lamp at " << lamp_at.x << ", " << lamp_at.z;
  }
}

}  // namespace
