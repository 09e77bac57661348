// An emissive surface on a dynamic object (a glowing crate, a lamp shade) moves with it: the
// light atlas bakes the static world's light, so it must not count that glow at the object's
// authored pose. The same quad made static lights the floor below it, which the test also
// checks, so the test fails if emissive geometry stops being baked at all.
#include <gtest/gtest.h>
#include <engine/scene_asset.h>

#include <cstdio>

#include "light_atlas/light_atlas.h"

namespace {

// A 2 x 2 m static floor and a 1 x 1 m quad 0.5 m above it facing down, glowing white, with
// the given mobility. No light, no sky.
gi::BakeInput floor_under_a_glowing_quad(engine::Mobility quad_mobility) {
  engine::SceneAsset a;
  engine::Primitive floor;
  floor.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  floor.normals.assign(4, glm::vec3(0, 1, 0));
  floor.indices = {0, 3, 2, 0, 2, 1};
  a.meshes.push_back({.name = "floor", .primitives = {floor}});
  engine::Primitive quad;
  quad.positions = {{-0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, {-0.5f, 0.5f, 0.5f}};
  quad.normals.assign(4, glm::vec3(0, -1, 0));
  quad.indices = {0, 1, 2, 0, 2, 3};  // front face down
  quad.material = 0;
  a.meshes.push_back({.name = "glow", .primitives = {quad}});
  engine::Material glow;
  glow.name = "glow";
  glow.emissive = glm::vec3(1.0f);
  a.materials.push_back(glow);
  engine::Node f;
  f.name = "floor";
  f.mesh = 0;
  f.gi.mobility = engine::Mobility::Static;
  a.nodes.push_back(f);
  engine::Node q;
  q.name = "glow";
  q.mesh = 1;
  q.gi.mobility = quad_mobility;
  a.nodes.push_back(q);
  return gi::bake_input_from(a);
}

double mean_floor_irradiance(engine::Mobility quad_mobility) {
  gi::LightAtlasSettings s = gi::light_atlas_preset("preview").value();
  s.texels_per_metre = 8.0f;
  s.include_direct = true;
  auto bake = gi::bake_light_atlas(floor_under_a_glowing_quad(quad_mobility), s);
  EXPECT_TRUE(bake) << bake.error().to_string();
  if (!bake) return -1.0;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t t = 0; t < bake->irradiance.size(); ++t) {
    if (!bake->valid[t]) continue;
    sum += static_cast<double>(bake->irradiance[t].y);
    ++n;
  }
  EXPECT_GT(n, 50u);
  return n > 0 ? sum / static_cast<double>(n) : -1.0;
}

}  // namespace

TEST(LightAtlasEmitters, ADynamicObjectsGlowIsNotBakedIntoTheStaticWorld) {
  const double with_static = mean_floor_irradiance(engine::Mobility::Static);
  const double with_dynamic = mean_floor_irradiance(engine::Mobility::Dynamic);
  std::printf("floor under a glowing quad: mean E %.4f (quad static), %.6f (quad dynamic)\n", with_static,
              with_dynamic);
  // A 1 x 1 m Lambertian emitter of radiance 1 at 0.5 m: E under its centre is about 1.7, the
  // floor's mean (most of it outside the quad's footprint) well above 0.1.
  EXPECT_GT(with_static, 0.1);
  EXPECT_EQ(with_dynamic, 0.0);
}
