// Rasterization of atlas layouts into per-texel world samples: positions on the surface,
// unit normals, the ownership rule and guaranteed samples for tiny triangles.
#include "uv/atlas_rasterizer.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <cmath>
#include <vector>

#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"
#include "uv/texel_triangle.h"

namespace {

gi::AtlasInputMesh unit_quad_z0() {
  gi::AtlasInputMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

}  // namespace

TEST(AtlasRasterizer, SamplesLieOnTheSurfaceWithUnitNormals) {
  const std::vector<gi::AtlasInputMesh> inputs{unit_quad_z0()};
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasTexels t = gi::rasterize_atlas(layout.value(), inputs);
  int inside = 0, conservative = 0;
  for (std::size_t i = 0; i < t.valid.size(); ++i) {
    if (!t.valid[i]) {
      EXPECT_EQ(t.coverage[i], gi::TexelCoverage::Empty);
      EXPECT_EQ(t.mesh[i], -1);
      continue;
    }
    (t.coverage[i] == gi::TexelCoverage::Inside ? inside : conservative)++;
    EXPECT_NEAR(t.position[i].z, 0.0f, 1e-6f);
    EXPECT_GE(t.position[i].x, -1e-5f);
    EXPECT_LE(t.position[i].x, 1.0f + 1e-5f);
    EXPECT_GE(t.position[i].y, -1e-5f);
    EXPECT_LE(t.position[i].y, 1.0f + 1e-5f);
    EXPECT_NEAR(t.normal[i].z, 1.0f, 1e-6f);
  }
  // 1 m^2 at 16 texels/m: 256 texel centres inside; the conservative ring adds at most the perimeter.
  EXPECT_NEAR(inside, 256, 34);
  EXPECT_LE(conservative, 4 * 17 + 4);
  // Texel spacing matches the density: neighbouring inside texels are 1/16 m apart.
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x + 1 < t.width; ++x) {
      const std::size_t i = t.index(x, y), j = t.index(x + 1, y);
      if (t.coverage[i] == gi::TexelCoverage::Inside && t.coverage[j] == gi::TexelCoverage::Inside) {
        EXPECT_NEAR(glm::length(t.position[j] - t.position[i]), 1.0f / 16.0f, 1e-4f);
      }
    }
}

TEST(AtlasRasterizer, InsetKeepsSamplesOffTheChartBorderAndOnTheSurface) {
  const std::vector<gi::AtlasInputMesh> inputs{unit_quad_z0()};
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasTexels raw = gi::rasterize_atlas(layout.value(), inputs);
  const gi::AtlasTexels t = gi::rasterize_atlas(layout.value(), inputs, 0.05f);
  ASSERT_EQ(t.valid, raw.valid);  // the inset moves samples, never the coverage
  // 0.05 texel is 1/320 m at 16 texels/m: no sample on the square's border line, where a
  // wall standing on it would begin.
  constexpr float kInset = 0.05f / 16.0f - 1e-6f;
  int on_border_before = 0, moved = 0;
  for (std::size_t i = 0; i < t.valid.size(); ++i) {
    if (!t.valid[i]) continue;
    const glm::vec3 p = t.position[i], q = raw.position[i];
    EXPECT_NEAR(p.z, 0.0f, 1e-6f);
    EXPECT_GE(std::min(p.x, p.y), kInset) << "texel " << i;
    EXPECT_LE(std::max(p.x, p.y), 1.0f - kInset) << "texel " << i;
    on_border_before += std::min(std::min(q.x, q.y), 1.0f - std::max(q.x, q.y)) < 1e-5f;
    // A sample moves towards the centroid of its triangle, a little more than the inset
    // along that line (at most 0.16 texel in these right triangles, from a far vertex).
    EXPECT_LE(glm::length(p - q), 0.2f / 16.0f) << "texel " << i;
    moved += glm::length(p - q) > 0.0f;
  }
  EXPECT_GT(on_border_before, 0) << "the raw raster has samples on the border (the case the inset is for)";
  EXPECT_GE(moved, on_border_before);
}

TEST(AtlasRasterizer, CentreInsideOwnershipGoesToTheLowestTriangle) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf", {.load_images = false});
  ASSERT_TRUE(asset.ok()) << asset.error().to_string();
  const auto inputs = gi::atlas_inputs_from(gi::bake_input_from(asset.value()));
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 8.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasTexels t = gi::rasterize_atlas(layout.value(), inputs);
  const glm::vec2 size(float(t.width), float(t.height));
  int checked = 0;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const std::size_t i = t.index(x, y);
      if (t.coverage[i] != gi::TexelCoverage::Inside) continue;
      const glm::vec2 centre(float(x) + 0.5f, float(y) + 0.5f);
      // The first (mesh, triangle) in order whose triangle contains the centre.
      const gi::AtlasMeshUv& m = layout->meshes[static_cast<std::size_t>(t.mesh[i])];
      for (std::size_t tri = 0; tri < static_cast<std::size_t>(t.triangle[i]); ++tri) {
        const glm::vec2 a = m.uv1[m.indices[3 * tri]] * size, b = m.uv1[m.indices[3 * tri + 1]] * size,
                        c = m.uv1[m.indices[3 * tri + 2]] * size;
        ASSERT_FALSE(gi::triangle_contains(centre, a, b, c)) << "a lower triangle contains texel " << x << ", " << y;
      }
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(AtlasRasterizer, TinyAndSliverTrianglesGetASample) {
  gi::AtlasInputMesh m = unit_quad_z0();
  // An isolated 1 mm triangle far away, and a sliver along the quad's bottom edge.
  m.positions.insert(m.positions.end(), {{10, 10, 10}, {10.001f, 10, 10}, {10, 10.001f, 10}});
  m.positions.insert(m.positions.end(), {{0, 0, 0}, {0, -0.001f, 0}, {1, 0, 0}});
  m.normals.assign(m.positions.size(), glm::vec3(0, 0, 1));
  m.indices.insert(m.indices.end(), {4, 5, 6, 7, 8, 9});
  const std::vector<gi::AtlasInputMesh> inputs{m};
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasMeshUv& uv = layout->meshes[0];
  EXPECT_EQ(uv.triangle_chart[3], uv.triangle_chart[0]) << "the sliver is part of the quad's chart";
  const gi::AtlasChart& tiny = layout->charts[uv.triangle_chart[2]];
  EXPECT_EQ(tiny.size, glm::ivec2(1)) << "a tiny chart still gets one texel";
  const gi::AtlasTexels t = gi::rasterize_atlas(layout.value(), inputs);
  const std::size_t i = t.index(tiny.origin.x, tiny.origin.y);
  ASSERT_TRUE(t.valid[i]);
  EXPECT_EQ(t.triangle[i], 2) << "the isolated tiny triangle owns its texel";
  EXPECT_LT(glm::length(t.position[i] - glm::vec3(10.0003f, 10.0003f, 10.0f)), 2e-3f);
  // The sliver's centroid texel is valid and in its chart.
  const glm::vec2 size(float(t.width), float(t.height));
  const glm::vec2 c = (uv.uv1[uv.indices[9]] + uv.uv1[uv.indices[10]] + uv.uv1[uv.indices[11]]) * size / 3.0f;
  const std::size_t s = t.index(int(c.x), int(c.y));
  ASSERT_TRUE(t.valid[s]);
  EXPECT_EQ(t.chart[s], static_cast<int>(uv.triangle_chart[3]));
}
