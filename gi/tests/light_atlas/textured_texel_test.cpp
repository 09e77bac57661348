// A light-atlas texel on a textured surface folds in the texture's mean over its footprint
// (material_lookup.h), not the colour at its sample point; texels an alpha MASK cuts out
// wholly are not lit (issue 33, docs/materials-in-bakes.md).
#include <gtest/gtest.h>
#include <gi/bake_input.h>

#include "raytrace/material_lookup.h"
#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace {

// A 2 m plate facing +y with uv0 over [0, 1]^2, its base colour a 128 x 128 checker of sRGB
// 255 and 0 (linear 1 and 0): 8 x 8 checker squares per texel at 8 texels per metre.
gi::BakeInput checker_plate(engine::AlphaMode alpha) {
  gi::BakeInput in;
  gi::BakeImage img{.name = "checker", .uri = "", .width = 128, .height = 128, .rgba8 = {}};
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      const std::uint8_t v = (x + y) % 2 ? 255 : 0;
      const std::uint8_t a = x < 64 ? 0 : 255;  // the left half transparent (read under MASK only)
      img.rgba8.insert(img.rgba8.end(), {v, v, v, a});
    }
  in.images.push_back(std::move(img));
  gi::BakeMaterial m;
  m.name = "checker";
  m.base_color = glm::vec3(0.8f);
  m.specular = 0.0f;  // Lambertian: albedo = base colour x texture
  m.base_color_texture.image = 0;
  // Clamped: with REPEAT the plate's left edge (u = 0) would blend in the opaque right column.
  m.base_color_texture.sampler.wrap_s = engine::TextureWrap::ClampToEdge;
  m.base_color_texture.sampler.wrap_t = engine::TextureWrap::ClampToEdge;
  m.alpha_mode = alpha;
  in.materials.push_back(m);
  gi::BakePrimitive p;
  p.positions = {{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}};
  p.normals.assign(4, {0, 1, 0});
  p.uv0 = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  p.indices = {0, 1, 2, 0, 2, 3};
  p.material = 0;
  in.meshes.push_back({"plate", {p}});
  in.instances.push_back({.name = "plate", .mesh = 0, .id = 0});
  return in;
}

TEST(TexturedTexel, AlbedoIsTheTexturesMeanOverTheFootprintNotAPointSample) {
  const gi::BakeInput in = checker_plate(engine::AlphaMode::Opaque);
  ASSERT_TRUE(gi::validate_bake_input(in));
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(in), {.texels_per_metre = 8.0f});
  ASSERT_TRUE(layout);
  auto s = gi::prepare_static_scene(in, *layout, gi::BakeLights::Static);
  ASSERT_TRUE(s) << s.error().to_string();
  int texels = 0, aliased = 0;
  for (std::size_t i = 0; i < s->texels.valid.size(); ++i) {
    if (!s->texels.valid[i]) continue;
    ++texels;
    const auto& tri = s->index.triangles[s->index.instance_first[s->static_instance[0]] +
                                         static_cast<std::uint32_t>(s->texels.triangle[i])];
    const gi::TexelFootprint f = gi::texel_footprint(*layout, s->texels.mesh[i], s->texels.triangle[i], i);
    const glm::vec3 mean = gi::footprint_albedo(s->scene, tri, f.centre, f.axis_u, f.axis_v);
    // 0.8 x the checker's mean 0.5; 3% for edge texels whose footprint the triangle clips.
    EXPECT_NEAR(mean.x, 0.4f, 0.012f) << "texel " << i;
    // One point at the finest level reads a single checker square: 0 or 0.8 (the texel's
    // centre lies on checker corners; 1/16 texel off it, on a square's centre).
    const glm::vec3 point = gi::albedo_at(s->scene, tri, f.centre + (f.axis_u + f.axis_v) / 16.0f, 0.0f);
    aliased += std::fabs(point.x - 0.4f) > 0.3f ? 1 : 0;
  }
  EXPECT_GT(texels, 200);
  EXPECT_GT(aliased, texels / 2) << "the checker is finer than a texel: point samples alias";
}

TEST(TexturedTexel, TexelsWhollyCutOutAreNotValid) {
  const gi::BakeInput opaque = checker_plate(engine::AlphaMode::Opaque);
  const gi::BakeInput masked = checker_plate(engine::AlphaMode::Mask);
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(opaque), {.texels_per_metre = 8.0f});
  ASSERT_TRUE(layout);
  auto a = gi::prepare_static_scene(opaque, *layout, gi::BakeLights::Static);
  auto b = gi::prepare_static_scene(masked, *layout, gi::BakeLights::Static);
  ASSERT_TRUE(a && b);
  int valid_a = 0, valid_b = 0;
  for (std::size_t i = 0; i < a->texels.valid.size(); ++i) {
    valid_a += a->texels.valid[i];
    valid_b += b->texels.valid[i];
    if (!b->texels.valid[i]) continue;
    // A kept texel lies (at least partly) on the opaque half: world x >= 0 within a texel.
    EXPECT_GT(b->texels.position[i].x, -0.125f - 1e-3f) << "texel " << i;
  }
  // Half the plate is cut out; the texels straddling the border stay: 16 of 17 columns
  // (the chart's texels) split into 8 kept, the border column and its neighbour partly.
  EXPECT_GE(static_cast<double>(valid_b) / valid_a, 0.45) << valid_b << " of " << valid_a;
  EXPECT_LE(static_cast<double>(valid_b) / valid_a, 10.0 / 17.0 + 1e-9) << valid_b << " of " << valid_a;
}

}  // namespace
