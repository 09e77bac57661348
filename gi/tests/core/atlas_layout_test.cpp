// Light-atlas layout on every scene in assets/: charts do not overlap, every triangle gets a
// sample, texel density holds, uv1 stays in [0, 1]; plus determinism, vertex splitting,
// degenerate triangles, density reduction and build timings.
#include "uv/atlas_layout.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace {

std::vector<std::filesystem::path> scene_files() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(GI_SOURCE_DIR "/assets"))
    if (e.path().extension() == ".gltf") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<gi::AtlasInputMesh> inputs_of(const std::filesystem::path& file) {
  auto asset = engine::load_gltf(file, {.load_images = false});
  EXPECT_TRUE(asset.ok()) << (asset.ok() ? "" : asset.error().to_string());
  return asset.ok() ? gi::atlas_inputs_from(gi::bake_input_from(asset.value())) : std::vector<gi::AtlasInputMesh>{};
}

float cross2(glm::vec2 a, glm::vec2 b, glm::vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

// Texel-space corners of triangle t of mesh m.
std::array<glm::vec2, 3> texel_corners(const gi::AtlasLayout& l, std::size_t m, std::size_t t) {
  std::array<glm::vec2, 3> p;
  for (int k = 0; k < 3; ++k)
    p[static_cast<std::size_t>(k)] = l.meshes[m].uv1[l.meshes[m].indices[3 * t + static_cast<std::size_t>(k)]] *
                                     glm::vec2(static_cast<float>(l.width), static_cast<float>(l.height));
  return p;
}

// Strict interior test (an independent re-implementation, not the rasterizer's).
bool strictly_inside(glm::vec2 q, const std::array<glm::vec2, 3>& p) {
  const float area = cross2(p[0], p[1], p[2]);
  if (area == 0.0f) return false;
  const float s = area > 0.0f ? 1.0f : -1.0f;
  return s * cross2(p[0], p[1], q) > 0.0f && s * cross2(p[1], p[2], q) > 0.0f && s * cross2(p[2], p[0], q) > 0.0f;
}

// Checks every property the atlas promises for one scene; returns the layout for more checks.
void check_scene_layout(const std::vector<gi::AtlasInputMesh>& inputs, const gi::AtlasLayout& l, float target) {
  ASSERT_GT(l.width, 0);
  ASSERT_GT(l.height, 0);
  EXPECT_EQ(l.texels_per_metre, target) << "these scenes fit at the requested density";
  ASSERT_EQ(l.meshes.size(), inputs.size());

  // uv1 inside [0, 1], one per output vertex.
  for (const gi::AtlasMeshUv& m : l.meshes) {
    ASSERT_EQ(m.uv1.size(), m.source_vertex.size());
    for (glm::vec2 uv : m.uv1) {
      EXPECT_TRUE(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f) << uv.x << ", " << uv.y;
    }
  }

  // Footprints inside the atlas, padding from the border and from each other.
  const int pad = l.padding_texels;
  for (std::size_t a = 0; a < l.charts.size(); ++a) {
    const gi::AtlasChart& c = l.charts[a];
    EXPECT_GE(c.origin.x, pad);
    EXPECT_GE(c.origin.y, pad);
    EXPECT_LE(c.origin.x + c.size.x + pad, l.width);
    EXPECT_LE(c.origin.y + c.size.y + pad, l.height);
    for (std::size_t b = a + 1; b < l.charts.size(); ++b) {
      const gi::AtlasChart& d = l.charts[b];
      const bool apart = c.origin.x + c.size.x + pad <= d.origin.x || d.origin.x + d.size.x + pad <= c.origin.x ||
                         c.origin.y + c.size.y + pad <= d.origin.y || d.origin.y + d.size.y + pad <= c.origin.y;
      EXPECT_TRUE(apart) << "charts " << a << " and " << b << " are closer than the padding";
    }
  }

  // No texel centre strictly inside triangles of two different charts; triangles stay in
  // their chart's footprint.
  std::vector<int> claim(static_cast<std::size_t>(l.width) * static_cast<std::size_t>(l.height), -1);
  int conflicts = 0;
  for (std::size_t m = 0; m < l.meshes.size(); ++m)
    for (std::size_t t = 0; t < l.meshes[m].triangle_chart.size(); ++t) {
      const auto p = texel_corners(l, m, t);
      const int chart = static_cast<int>(l.meshes[m].triangle_chart[t]);
      const gi::AtlasChart& c = l.charts[static_cast<std::size_t>(chart)];
      for (const glm::vec2& q : p) {
        EXPECT_GT(q.x, static_cast<float>(c.origin.x));
        EXPECT_GT(q.y, static_cast<float>(c.origin.y));
        EXPECT_LT(q.x, static_cast<float>(c.origin.x + c.size.x));
        EXPECT_LT(q.y, static_cast<float>(c.origin.y + c.size.y));
      }
      const glm::vec2 lo = glm::min(p[0], glm::min(p[1], p[2])), hi = glm::max(p[0], glm::max(p[1], p[2]));
      for (int y = std::max(0, int(lo.y)); y <= std::min(l.height - 1, int(hi.y)); ++y)
        for (int x = std::max(0, int(lo.x)); x <= std::min(l.width - 1, int(hi.x)); ++x) {
          if (!strictly_inside(glm::vec2(float(x) + 0.5f, float(y) + 0.5f), p)) continue;
          int& owner = claim[static_cast<std::size_t>(y * l.width + x)];
          if (owner >= 0 && owner != chart) ++conflicts;
          owner = chart;
        }
    }
  EXPECT_EQ(conflicts, 0) << "texels claimed by the interiors of two charts";

  // Every triangle: the texel under its uv centroid is valid and owned by its own chart.
  const gi::AtlasTexels texels = gi::rasterize_atlas(l, inputs);
  std::size_t owning = 0, triangles = 0;
  std::vector<std::vector<bool>> owns(l.meshes.size());
  for (std::size_t m = 0; m < l.meshes.size(); ++m) owns[m].assign(l.meshes[m].triangle_chart.size(), false);
  for (std::size_t i = 0; i < texels.valid.size(); ++i)
    if (texels.valid[i])
      owns[static_cast<std::size_t>(texels.mesh[i])][static_cast<std::size_t>(texels.triangle[i])] = true;
  for (std::size_t m = 0; m < l.meshes.size(); ++m)
    for (std::size_t t = 0; t < l.meshes[m].triangle_chart.size(); ++t) {
      const auto p = texel_corners(l, m, t);
      const glm::vec2 centroid = (p[0] + p[1] + p[2]) / 3.0f;
      const std::size_t i = texels.index(int(centroid.x), int(centroid.y));
      ASSERT_TRUE(texels.valid[i]) << "mesh " << m << " triangle " << t << " has no sample";
      EXPECT_EQ(texels.chart[i], static_cast<int>(l.meshes[m].triangle_chart[t]));
      ++triangles;
      if (owns[m][t]) ++owning;
    }
  EXPECT_EQ(owning, triangles) << "in these scenes every triangle owns at least one texel";

  // Texel density per chart: sqrt(uv area in texels / world area) within a factor 2 of the target.
  std::vector<double> uv_area(l.charts.size(), 0.0);
  for (std::size_t m = 0; m < l.meshes.size(); ++m)
    for (std::size_t t = 0; t < l.meshes[m].triangle_chart.size(); ++t) {
      const auto p = texel_corners(l, m, t);
      uv_area[l.meshes[m].triangle_chart[t]] += 0.5 * std::fabs(double(cross2(p[0], p[1], p[2])));
    }
  for (std::size_t c = 0; c < l.charts.size(); ++c) {
    if (l.charts[c].area_m2 < 1e-6) continue;
    const double density = std::sqrt(uv_area[c] / l.charts[c].area_m2);
    EXPECT_GT(density, 0.5 * double(target)) << "chart " << c;
    EXPECT_LT(density, 2.0 * double(target)) << "chart " << c;
  }
}

}  // namespace

TEST(AtlasLayout, EverySceneHasNonOverlappingSampledChartsAtTheRequestedDensity) {
  const auto files = scene_files();
  ASSERT_GE(files.size(), 6u);
  for (const auto& file : files) {
    for (float density : {8.0f, 32.0f}) {
      SCOPED_TRACE(file.filename().string() + " at " + std::to_string(density) + " texels/m");
      const auto inputs = inputs_of(file);
      ASSERT_FALSE(inputs.empty());
      auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = density});
      ASSERT_TRUE(layout.ok()) << layout.error().to_string();
      check_scene_layout(inputs, layout.value(), density);
    }
  }
}

TEST(AtlasLayout, BuildingTwiceGivesIdenticalLayouts) {
  const auto inputs = inputs_of(GI_SOURCE_DIR "/assets/demo_level.gltf");
  auto a = gi::build_atlas_layout(inputs, {.texels_per_metre = 24.0f});
  auto b = gi::build_atlas_layout(inputs, {.texels_per_metre = 24.0f});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->width, b->width);
  EXPECT_EQ(a->height, b->height);
  ASSERT_EQ(a->charts.size(), b->charts.size());
  for (std::size_t c = 0; c < a->charts.size(); ++c) {
    EXPECT_EQ(a->charts[c].origin, b->charts[c].origin);
    EXPECT_EQ(a->charts[c].size, b->charts[c].size);
  }
  ASSERT_EQ(a->meshes.size(), b->meshes.size());
  for (std::size_t m = 0; m < a->meshes.size(); ++m) {
    EXPECT_EQ(a->meshes[m].indices, b->meshes[m].indices);
    EXPECT_EQ(a->meshes[m].source_vertex, b->meshes[m].source_vertex);
    EXPECT_EQ(a->meshes[m].triangle_chart, b->meshes[m].triangle_chart);
    EXPECT_TRUE(a->meshes[m].uv1 == b->meshes[m].uv1);
  }
}

namespace {

// A unit cube with 8 shared vertices (so every vertex is used by three faces' charts).
gi::AtlasInputMesh shared_vertex_cube() {
  gi::AtlasInputMesh m;
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
  m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
               2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  m.id = 42;
  return m;
}

}  // namespace

TEST(AtlasLayout, VerticesSharedByChartsAreSplitWithARemap) {
  const std::vector<gi::AtlasInputMesh> inputs{shared_vertex_cube()};
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasMeshUv& m = layout->meshes[0];
  EXPECT_EQ(m.id, 42);
  EXPECT_EQ(layout->charts.size(), 6u) << "one chart per cube face";
  EXPECT_EQ(m.source_vertex.size(), 24u) << "each corner is split into one vertex per face";
  for (std::uint32_t v = 0; v < 8; ++v) EXPECT_EQ(m.source_vertex[v], v) << "original vertices keep their index";
  ASSERT_EQ(m.indices.size(), inputs[0].indices.size());
  for (std::size_t k = 0; k < m.indices.size(); ++k)
    EXPECT_EQ(m.source_vertex[m.indices[k]], inputs[0].indices[k]) << "the remap gives back the input triangle";
  // Within a chart, an output vertex is used by that chart only.
  std::vector<int> chart_of_vertex(m.source_vertex.size(), -1);
  for (std::size_t k = 0; k < m.indices.size(); ++k) {
    int& c = chart_of_vertex[m.indices[k]];
    const int tc = static_cast<int>(m.triangle_chart[k / 3]);
    EXPECT_TRUE(c < 0 || c == tc);
    c = tc;
  }
  check_scene_layout(inputs, layout.value(), 16.0f);
}

TEST(AtlasLayout, DegenerateTrianglesGetValidUvAndASample) {
  gi::AtlasInputMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},  // a quad
                 {1, 1, 0}, {1, 1, 0},                        // a point triangle at its corner
                 {5, 5, 5}, {6, 6, 6}, {7, 7, 7},             // an isolated collinear triangle
                 {9, 9, 9}};                                  // an isolated point triangle
  m.indices = {0, 1, 2, 0, 2, 3, 4, 5, 4, 6, 7, 8, 9, 9, 9};
  const std::vector<gi::AtlasInputMesh> inputs{m};
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 8.0f});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasMeshUv& uv = layout->meshes[0];
  EXPECT_EQ(uv.triangle_chart[2], uv.triangle_chart[0]) << "the point triangle joins the chart it touches";
  for (glm::vec2 p : uv.uv1)
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1);
  const gi::AtlasTexels texels = gi::rasterize_atlas(layout.value(), inputs);
  const glm::vec2 size(float(layout->width), float(layout->height));
  for (std::size_t t = 0; t < 5; ++t) {
    glm::vec2 c(0.0f);
    for (int k = 0; k < 3; ++k) c += uv.uv1[uv.indices[3 * t + std::size_t(k)]] * size / 3.0f;
    const std::size_t i = texels.index(int(c.x), int(c.y));
    EXPECT_TRUE(texels.valid[i]) << "triangle " << t;
    EXPECT_TRUE(std::isfinite(texels.position[i].x) && std::isfinite(texels.normal[i].x));
    EXPECT_NEAR(glm::length(texels.normal[i]), 1.0f, 1e-4f);
  }
}

TEST(AtlasLayout, ContentTooLargeForMaxSizeLowersAndReportsTheDensity) {
  gi::AtlasInputMesh m;  // a 100 m x 100 m floor and a 3 m x 3 m wall
  m.positions = {{0, 0, 0}, {100, 0, 0}, {100, 0, 100}, {0, 0, 100}, {0, 0, 0}, {3, 0, 0}, {3, 3, 0}, {0, 3, 0}};
  m.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7};
  const std::vector<gi::AtlasInputMesh> inputs{m};
  auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 128.0f, .max_atlas_size = 1024});
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  EXPECT_TRUE(layout->density_reduced());
  EXPECT_EQ(layout->requested_texels_per_metre, 128.0f);
  EXPECT_LT(layout->texels_per_metre, 10.3f);
  EXPECT_GT(layout->texels_per_metre, 5.0f) << "not needlessly low";
  EXPECT_LE(layout->width, 1024);
  EXPECT_LE(layout->height, 1024);
  // The reported density is the one achieved.
  const gi::AtlasMeshUv& uv = layout->meshes[0];
  const glm::vec2 size(float(layout->width), float(layout->height));
  const glm::vec2 a = uv.uv1[uv.indices[0]] * size, b = uv.uv1[uv.indices[1]] * size, c = uv.uv1[uv.indices[2]] * size;
  const float texel_area = 0.5f * std::fabs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  EXPECT_NEAR(std::sqrt(texel_area / 5000.0f), layout->texels_per_metre, 1e-3f * layout->texels_per_metre);
}

TEST(AtlasLayout, TimesDemoLevelBuildAndRasterization) {
  const auto inputs = inputs_of(GI_SOURCE_DIR "/assets/demo_level.gltf");
#ifdef NDEBUG
  const std::vector<float> densities{32.0f, 128.0f};
#else
  const std::vector<float> densities{32.0f};  // a 4096 x 4096 atlas takes too long unoptimized
#endif
  for (float density : densities) {
    const auto t0 = std::chrono::steady_clock::now();
    auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = density});
    const auto t1 = std::chrono::steady_clock::now();
    ASSERT_TRUE(layout.ok()) << layout.error().to_string();
    const gi::AtlasTexels texels = gi::rasterize_atlas(layout.value(), inputs);
    const auto t2 = std::chrono::steady_clock::now();
    std::size_t valid = 0;
    for (std::uint8_t v : texels.valid) valid += v;
    const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
    std::printf(
        "[ timing ] demo_level at %.0f texels/m: atlas %d x %d (achieved %.2f texels/m), %zu charts, "
        "%zu valid texels (%.1f%%); build %.2f ms, rasterize %.2f ms\n",
        double(density), layout->width, layout->height, double(layout->texels_per_metre), layout->charts.size(), valid,
        100.0 * double(valid) / double(texels.valid.size()), ms(t1 - t0), ms(t2 - t1));
  }
}
