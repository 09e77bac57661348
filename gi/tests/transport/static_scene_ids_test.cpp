// A StaticBakeScene's caster numbers only the static instances; its index numbers all of
// them. Everything that looks a hit up in the index by hit.instance (PathTracer) needs
// snapshot_id_caster's view: the glossy sweeps' path-traced truth shaded the corridor's hits
// on the demo level's crate-room triangles without it (docs/reflection_probes.md, "Accuracy").
#include <gtest/gtest.h>
#include <gi/bake_input.h>

#include <cmath>

#include "core/random.h"
#include "raytrace/path_tracer.h"
#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace {

gi::BakeMesh quad_mesh(const char* name, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  gi::BakePrimitive p;
  p.positions = {c, c + u, c + u + v, c + v};
  p.indices = {0, 1, 2, 0, 2, 3};
  p.material = 0;
  gi::BakeMesh m;
  m.name = name;
  m.primitives.push_back(std::move(p));
  return m;
}

// A dynamic quad far away first, then a static floor and a static wall at x = 4 facing -x,
// under a uniform sky.
gi::BakeInput dynamic_first() {
  gi::BakeInput in;
  in.name = "ids.gltf";
  in.materials.push_back(gi::BakeMaterial{.base_color = glm::vec3(0.5f), .roughness = 1.0f});
  in.meshes.push_back(quad_mesh("crate", {100, 0, 0}, {0, 0, 1}, {1, 0, 0}));
  in.meshes.push_back(quad_mesh("floor", {0, 0, 0}, {0, 0, 4}, {4, 0, 0}));
  in.meshes.push_back(quad_mesh("wall", {4, 0, 0}, {0, 0, 4}, {0, 3, 0}));
  in.instances.push_back(gi::BakeInstance{.name = "crate", .mesh = 0, .mobility = gi::BakeMobility::Dynamic, .id = 0});
  in.instances.push_back(gi::BakeInstance{.name = "floor", .mesh = 1, .id = 1});
  in.instances.push_back(gi::BakeInstance{.name = "wall", .mesh = 2, .id = 2});
  in.environment.sky_radiance = glm::vec3(1.0f);
  return in;
}

// Whether p lies on triangle `tri` (its plane, inside its edges).
bool on_triangle(const gi::ShadingTriangle& tri, const glm::vec3& p) {
  const glm::vec3 n = glm::normalize(glm::cross(tri.e1, tri.e2)), d = p - tri.p0;
  if (std::abs(glm::dot(d, n)) > 1e-4f) return false;
  const float a = glm::dot(tri.e1, tri.e1), b = glm::dot(tri.e1, tri.e2), c = glm::dot(tri.e2, tri.e2);
  const float pd1 = glm::dot(d, tri.e1), pd2 = glm::dot(d, tri.e2), det = a * c - b * b;
  const float u = (c * pd1 - b * pd2) / det, v = (a * pd2 - b * pd1) / det;
  return u >= -1e-4f && v >= -1e-4f && u + v <= 1.0f + 1e-4f;
}

TEST(SnapshotIdCaster, AHitNamesTheTriangleItLandedOnWhenADynamicInstanceComesFirst) {
  const gi::BakeInput in = dynamic_first();
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(in), {.texels_per_metre = 4.0f});
  ASSERT_TRUE(layout) << layout.error().to_string();
  auto s = gi::prepare_static_scene(in, *layout, gi::BakeLights::Static);
  ASSERT_TRUE(s) << s.error().to_string();
  const gi::Ray ray{glm::vec3(1.0f, 1.0f, 2.0f), 0.0f, glm::vec3(1.0f, 0.0f, 0.0f)};
  const glm::vec3 at = ray.origin + 3.0f * ray.direction;  // on the wall
  const gi::Hit raw = s->caster->intersect(ray);
  ASSERT_TRUE(raw.valid());
  EXPECT_TRUE(on_triangle(s->index.triangles[s->triangle_of(raw)], at));
  // The caster's own id read as the index's: the dynamic crate's triangles.
  EXPECT_FALSE(on_triangle(s->index.triangles[s->index.instance_first[raw.instance] + raw.primitive], at));
  const auto view = gi::snapshot_id_caster(*s);
  const gi::Hit hit = view->intersect(ray);
  ASSERT_TRUE(hit.valid());
  EXPECT_EQ(hit.instance, 2u);
  EXPECT_TRUE(on_triangle(s->index.triangles[s->index.instance_first[hit.instance] + hit.primitive], at));
  EXPECT_FALSE(view->occluded(gi::Ray{glm::vec3(1.0f, 1.0f, 2.0f), 0.0f, glm::vec3(-1.0f, 0.0f, 0.0f)}));
}

// The path tracer on that view: the wall's front under a uniform sky of radiance 1 reflects
// at most its albedo (about 0.5: diffuse 0.48, specular a few percent) and, the floor below it
// being half as bright as the sky, at least 0.3. Through the caster's own ids (the wall is
// its static instance 1, the index's 2) a hit was shaded on the floor's triangles, edge-on:
// black.
TEST(SnapshotIdCaster, ThePathTracerShadesTheStaticWorldThroughIt) {
  const gi::BakeInput in = dynamic_first();
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(in), {.texels_per_metre = 4.0f});
  ASSERT_TRUE(layout);
  auto s = gi::prepare_static_scene(in, *layout, gi::BakeLights::Static);
  ASSERT_TRUE(s);
  const auto view = gi::snapshot_id_caster(*s);
  const gi::PathTracer pt(s->scene, s->index, *view, {});
  gi::Pcg32 rng = gi::Pcg32::for_item(1, 0);
  double sum = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i)
    sum += static_cast<double>(pt.radiance(gi::Ray{glm::vec3(1.0f, 1.0f, 2.0f), 0.0f, glm::vec3(1, 0, 0)}, rng).x);
  EXPECT_GT(sum / n, 0.3);
  EXPECT_LT(sum / n, 0.55);
}

}  // namespace
