// The light-atlas provider in the real renderer (llvmpipe through EGL; never skipped): a
// constant atlas of irradiance pi x a shades exactly like the renderer's constant-ambient
// stand-in of radiance a, and an atlas lit on one chart lights exactly that chart's pixels.
#include "system/light_atlas_lighting.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/renderer.h>
#include <engine/scene.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>

#include "bundle/geometry_hash.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kSize = 96;

// The Cornell box with its lights switched off: only the emissive quad and indirect light.
// The Cornell box without its light; `lambertian` removes the materials' specular layer
// (KHR_materials_specular factor 0), so that the BRDF's reflectance is the base colour
// exactly at every view angle.
engine::SceneAsset dark_cornell(bool lambertian = false) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset.ok()) << asset.error().to_string();
  for (engine::NamedLight& l : asset->lights) l.light.enabled = false;
  if (lambertian)
    for (engine::Material& m : asset->materials) m.specular_factor = 0.0f;
  return std::move(asset).value();
}

// A bake of `asset`'s layout whose texels all hold `fill`.
gi::LightAtlasBake uniform_bake(const engine::SceneAsset& asset, glm::vec3 fill) {
  gi::LightAtlasBake b;
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(gi::bake_input_from(asset)), {.texels_per_metre = 8.0f});
  EXPECT_TRUE(layout.ok()) << layout.error().to_string();
  b.layout = std::move(layout).value();
  b.width = b.layout.width;
  b.height = b.layout.height;
  b.irradiance.assign(static_cast<std::size_t>(b.width * b.height), fill);
  b.valid.assign(b.irradiance.size(), 1);
  return b;
}

std::unique_ptr<gi::LightAtlasLighting> provider_for(gi::LightAtlasBake bake, engine::SceneAsset& asset) {
  auto p = gi::LightAtlasLighting::from_bake(std::move(bake), asset);
  EXPECT_TRUE(p.ok()) << p.error().to_string();
  return p.ok() ? std::move(p).value() : nullptr;
}

// The Cornell scene (with uv1), a renderer for it, and a headless context.
struct Fixture {
  engine::GpuContext ctx;
  engine::Scene scene;
  std::unique_ptr<engine::Renderer> renderer;

  engine::ImageRgbaF render(engine::IndirectLightProvider* provider, float stand_in_ambient) {
    renderer->set_indirect_light(provider);
    renderer->settings().stand_in_ambient = stand_in_ambient;
    renderer->render(scene.registry, engine::find_camera(scene.registry));
    return renderer->read_hdr();
  }
};

std::optional<Fixture> make_fixture(engine::SceneAsset uv1_asset) {
  auto ctx = engine::GpuContext::create_headless();
  EXPECT_TRUE(ctx.ok()) << "headless GL context creation failed: " << ctx.error().to_string();
  if (!ctx) return std::nullopt;
  Fixture f{std::move(ctx).value(), engine::instantiate(std::move(uv1_asset)), nullptr};
  engine::RenderSettings rs;
  rs.width = rs.height = kSize;
  rs.shadow_map_size = 256;
  auto r = engine::Renderer::create(f.scene.assets, rs);
  EXPECT_TRUE(r.ok()) << r.error().to_string();
  if (!r) return std::nullopt;
  f.renderer = std::move(r).value();
  return f;
}

// Möller-Trumbore; distance along the ray or +inf.
double hit_distance(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::fabs(det) < 1e-14) return std::numeric_limits<double>::infinity();
  const glm::dvec3 s = o - a;
  const double u = glm::dot(s, p) / det;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) / det;
  const double t = glm::dot(e2, q) / det;
  if (u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 1e-6) return std::numeric_limits<double>::infinity();
  return t;
}

// Per pixel (rows top to bottom), the atlas chart of the nearest static triangle under the
// pixel centre (-1: none), by ray casting the layout's input meshes on the CPU.
std::vector<int> chart_per_pixel(const engine::Scene& scene, const gi::AtlasLayout& layout,
                                 const std::vector<gi::AtlasInputMesh>& inputs) {
  const engine::Entity camera = engine::find_camera(scene.registry);
  const engine::Camera& cam = scene.registry.get<engine::Camera>(camera);
  const glm::mat4 world = scene.registry.get<engine::WorldTransform>(camera).matrix;
  const float aspect = cam.aspect > 0.0f ? cam.aspect : 1.0f;
  const glm::dmat4 inv(
      glm::inverse(glm::perspective(cam.yfov_rad, aspect, cam.znear_m, cam.zfar_m) * glm::inverse(world)));
  std::vector<int> chart(static_cast<std::size_t>(kSize * kSize), -1);
  for (int py = 0; py < kSize; ++py) {
    for (int px = 0; px < kSize; ++px) {
      const double x = (px + 0.5) / kSize * 2.0 - 1.0, y = 1.0 - (py + 0.5) / kSize * 2.0;
      const glm::dvec4 n = inv * glm::dvec4(x, y, -1.0, 1.0), f = inv * glm::dvec4(x, y, 1.0, 1.0);
      const glm::dvec3 o = glm::dvec3(n) / n.w, d = glm::normalize(glm::dvec3(f) / f.w - o);
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t m = 0; m < inputs.size(); ++m) {
        const auto& in = inputs[m];
        for (std::size_t t = 0; 3 * t < in.indices.size(); ++t) {
          const double h = hit_distance(o, d, glm::dvec3(in.positions[in.indices[3 * t]]),
                                        glm::dvec3(in.positions[in.indices[3 * t + 1]]),
                                        glm::dvec3(in.positions[in.indices[3 * t + 2]]));
          if (h < best) {
            best = h;
            chart[static_cast<std::size_t>(py * kSize + px)] = static_cast<int>(layout.meshes[m].triangle_chart[t]);
          }
        }
      }
    }
  }
  return chart;
}

}  // namespace

TEST(LightAtlasLighting, ConstantAtlasMatchesTheConstantAmbientStandIn) {
  constexpr float kAmbient = 0.5f;  // W/(m^2 sr); the atlas holds E = pi x L
  engine::SceneAsset asset = dark_cornell();
  auto provider = provider_for(uniform_bake(asset, glm::vec3(kPi * kAmbient)), asset);
  ASSERT_TRUE(provider);
  EXPECT_STREQ(provider->label(), "light atlas");
  auto f = make_fixture(std::move(asset));
  ASSERT_TRUE(f);

  const engine::ImageRgbaF stand_in = f->render(nullptr, kAmbient);
  const engine::ImageRgbaF atlas = f->render(provider.get(), /*ignored*/ 0.0f);
  ASSERT_TRUE(provider->frame().irradiance_atlas_texture);
  ASSERT_EQ(atlas.pixels.size(), stand_in.pixels.size());
  // Tolerance: 1e-3 relative + 1e-7 absolute per channel, one step of the renderer's RGBA16F
  // HDR target (11-bit mantissa). Bilinear reads of a constant texture return it exactly;
  // albedo/pi x (pi a) and albedo x a differ only by float rounding, which can flip one
  // half-float rounding step.
  double max_rel = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < atlas.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const double a = stand_in.pixels[i], b = atlas.pixels[i];
    sum += a;
    max_rel = std::max(max_rel, std::fabs(a - b) / std::max(a, 1e-7));
    ASSERT_NEAR(b, a, 1e-3 * a + 1e-7) << "pixel " << i / 4 % kSize << ", " << i / 4 / kSize << " channel " << i % 4;
  }
  std::printf("constant atlas vs stand-in: max relative difference %.3g over %d pixels\n", max_rel, kSize * kSize);
  EXPECT_GT(sum / (kSize * kSize * 3), 0.05) << "the ambient term must be visible";
}

TEST(LightAtlasLighting, OneLitChartLightsExactlyItsPixels) {
  engine::SceneAsset original = dark_cornell(/*lambertian=*/true);
  const std::vector<gi::AtlasInputMesh> inputs = gi::atlas_inputs_from(gi::bake_input_from(original));
  gi::LightAtlasBake dark = uniform_bake(original, glm::vec3(0.0f));
  gi::LightAtlasBake lit = dark;
  std::size_t chart = 0;  // the largest chart
  for (std::size_t c = 0; c < lit.layout.charts.size(); ++c)
    if (lit.layout.charts[c].area_m2 > lit.layout.charts[chart].area_m2) chart = c;
  const gi::AtlasChart& ch = lit.layout.charts[chart];
  const glm::vec3 kIrradiance(kPi, 2.0f * kPi, 0.5f * kPi);
  // The footprint plus the one-texel ring a dilation pass fills (bilinear reads inside the
  // chart reach it; with padding 2 no other chart reads it).
  ASSERT_GE(lit.layout.padding_texels, 2);
  for (int y = ch.origin.y - 1; y < ch.origin.y + ch.size.y + 1; ++y)
    for (int x = ch.origin.x - 1; x < ch.origin.x + ch.size.x + 1; ++x)
      lit.irradiance[static_cast<std::size_t>(y * lit.width + x)] = kIrradiance;

  engine::SceneAsset asset = original;
  auto dark_provider = provider_for(std::move(dark), asset);
  engine::SceneAsset again = original;
  auto lit_provider = provider_for(lit, again);
  ASSERT_TRUE(dark_provider && lit_provider);
  auto f = make_fixture(std::move(asset));
  ASSERT_TRUE(f);
  const engine::ImageRgbaF base = f->render(dark_provider.get(), 0.0f);
  const engine::ImageRgbaF with = f->render(lit_provider.get(), 0.0f);
  const std::vector<int> charts = chart_per_pixel(f->scene, lit.layout, inputs);

  // Material albedo of the chart (one mesh, one material in the Cornell box's charts).
  const gi::AtlasMeshUv& mesh_uv = lit.layout.meshes[ch.mesh];
  std::size_t first_triangle = 0;
  while (mesh_uv.triangle_chart[first_triangle] != chart) ++first_triangle;
  const engine::Mesh& mesh =
      original.meshes[static_cast<std::size_t>(original.nodes[static_cast<std::size_t>(mesh_uv.id)].mesh)];
  std::size_t prim = 0;  // primitives are concatenated in order (atlas_inputs_from)
  for (std::size_t t = first_triangle; t >= mesh.primitives[prim].indices.size() / 3; ++prim)
    t -= mesh.primitives[prim].indices.size() / 3;
  const glm::vec4 base_color = original.materials[static_cast<std::size_t>(mesh.primitives[prim].material)].base_color;

  int inside = 0, outside = 0;
  for (int py = 1; py + 1 < kSize; ++py) {
    for (int px = 1; px + 1 < kSize; ++px) {
      int hits = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          hits += charts[static_cast<std::size_t>((py + dy) * kSize + px + dx)] == static_cast<int>(chart);
      const std::size_t p = static_cast<std::size_t>(py * kSize + px) * 4;
      if (hits == 9) {  // well inside the chart: albedo/pi x E added
        ++inside;
        for (int c = 0; c < 3; ++c) {
          const double expected = base.pixels[p + static_cast<std::size_t>(c)] + base_color[c] * kIrradiance[c] / kPi;
          // 1e-3 relative: one rounding step of the RGBA16F HDR target.
          ASSERT_NEAR(with.pixels[p + static_cast<std::size_t>(c)], expected, 1e-3 * expected)
              << "pixel " << px << ", " << py << " inside the lit chart";
        }
      } else if (hits == 0) {  // well outside: bit-identical
        ++outside;
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(with.pixels[p + static_cast<std::size_t>(c)], base.pixels[p + static_cast<std::size_t>(c)])
              << "pixel " << px << ", " << py << " outside the lit chart";
      }
    }
  }
  std::printf("lit chart %zu (%.3f m^2): %d pixels inside, %d outside checked\n", chart, ch.area_m2, inside, outside);
  EXPECT_GT(inside, 200);
  EXPECT_GT(outside, 200);
}

TEST(LightAtlasLighting, LoadsABundleAndGivesTheSceneUv1) {
  engine::SceneAsset asset = dark_cornell();
  const std::filesystem::path dir = std::filesystem::path(GI_BINARY_DIR) / "test_output" / "light_atlas_lighting_test";
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(gi::save_light_atlas(dir, uniform_bake(asset, glm::vec3(1.0f)), gi::bake_input_from(asset)).ok());
  auto bake = gi::load_light_atlas(dir, gi::bake_input_from(asset));
  ASSERT_TRUE(bake.ok()) << bake.error().to_string();
  auto provider = gi::LightAtlasLighting::from_bake(std::move(*bake), asset);
  ASSERT_TRUE(provider.ok()) << provider.error().to_string();
  EXPECT_GT((*provider)->atlas_width(), 0);
  for (const engine::Node& n : asset.nodes) {
    if (n.mesh < 0) continue;
    for (const engine::Primitive& p : asset.meshes[static_cast<std::size_t>(n.mesh)].primitives)
      EXPECT_EQ(p.uv1.size(), p.positions.size()) << "every static primitive has TEXCOORD_1";
  }
  // Loading again into the uv1 scene: same triangles, so the bundle is not stale.
  EXPECT_EQ(gi::scene_geometry_hash(gi::bake_input_from(asset)),
            gi::scene_geometry_hash(gi::bake_input_from(dark_cornell())));

  engine::SceneAsset moved = dark_cornell();
  moved.nodes[1].translation.x += 0.05f;
  auto stale = gi::load_light_atlas(dir, gi::bake_input_from(moved));
  ASSERT_FALSE(stale.ok());
  EXPECT_NE(stale.error().to_string().find("stale"), std::string::npos) << stale.error().to_string();
}

TEST(LightAtlasLighting, LoadIntoAnInstantiatedSceneLeavesItAndGivesEachInstanceAnAtlasMesh) {
  // Two static nodes share one quad mesh: each gets its own atlas mesh, the scene keeps one.
  engine::SceneAsset asset;
  engine::Primitive quad;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  asset.meshes.push_back(engine::Mesh{"quad", {quad}});
  for (int i = 0; i < 2; ++i) {
    engine::Node n;
    n.name = "quad" + std::to_string(i);
    n.mesh = 0;
    n.translation = glm::vec3(2.0f * static_cast<float>(i), 0.0f, 0.0f);
    n.gi.mobility = engine::Mobility::Static;
    asset.nodes.push_back(n);
  }
  const std::filesystem::path dir =
      std::filesystem::path(GI_BINARY_DIR) / "test_output" / "light_atlas_lighting_shared";
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(gi::save_light_atlas(dir, uniform_bake(asset, glm::vec3(1.0f)), gi::bake_input_from(asset)).ok());

  engine::Scene scene = engine::instantiate(asset);
  auto bake = gi::load_light_atlas(dir, gi::bake_input_from(scene));
  ASSERT_TRUE(bake.ok()) << bake.error().to_string();
  auto provider = gi::LightAtlasLighting::from_bake(*bake, scene);
  ASSERT_TRUE(provider.ok()) << provider.error().to_string();
  // The scene is left as the game made it: one mesh, both nodes on it, no TEXCOORD_1.
  ASSERT_EQ(scene.assets.meshes.size(), 1u);
  EXPECT_TRUE(scene.assets.meshes[0].primitives[0].uv1.empty());
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_EQ(scene.registry.get<engine::MeshRenderer>(scene.node_entities[i]).mesh, 0u) << "node " << i;
  // Each instance gets its own atlas mesh, with its own region of the atlas.
  const std::span<const engine::AtlasMesh> atlas = (*provider)->atlas_meshes();
  ASSERT_EQ(atlas.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(atlas[i].entity, scene.node_entities[i]) << "node " << i;
    EXPECT_EQ(atlas[i].source_mesh, 0u);
    ASSERT_EQ(atlas[i].mesh.primitives.size(), 1u);
    EXPECT_EQ(atlas[i].mesh.primitives[0].uv1.size(), 4u);
    EXPECT_EQ(atlas[i].mesh.primitives[0].positions, quad.positions);
  }
  EXPECT_NE(atlas[0].mesh.primitives[0].uv1, atlas[1].mesh.primitives[0].uv1);
}
