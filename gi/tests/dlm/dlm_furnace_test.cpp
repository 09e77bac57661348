// White furnace room for the renderer's split of indirect light on a glossy static surface
// (issue 36, "Energy"): a closed box whose every surface is the same emissive material, so
// the light that arrives at the glossy floor after at least one reflection is the same from
// every direction, L = L_e a / (1 - a) (a: the hemispherical albedo every bake folds a
// surface to). The floor must then reflect exactly L x its directional albedo, the glTF BRDF's
// f cos integrated over the hemisphere (numerically here, not the renderer's table).
//
// What the renderer does there (engine/shaders/forward.frag.glsl, the indirect block): the
// diffuse share from the atlas's irradiance E, E / pi x albedo_diffuse (the table), plus the
// specular share from the directional light maps, engine::directional_specular (the C++ twin
// of the shader's function, kept equal by DirectionalRadiance.GlslTwinAgreesWithTheCpp) over
// the bins gi::bake_dlm baked. The atlas's E is taken as exact (pi L: the atlas's own energy is
// tested in gi/tests/light_atlas); the maps are baked with photons. Checked at five view
// angles over the floor's texels: diffuse + specular = L x directional albedo within 2%
// (nothing counted twice, nothing lost: neither the bins' mean nor the lookup's normalization
// nor the table's split may be off).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include <engine/directional_radiance.h>
#include <engine/gltf_brdf.h>
#include <engine/scene_asset.h>
#include <gi/bake_input.h>

#include "dlm/dlm.h"
#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace {

void add_quad(engine::Primitive& p, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const auto base = static_cast<std::uint32_t>(p.positions.size());
  const glm::vec3 n = glm::normalize(glm::cross(u, v));
  p.positions.insert(p.positions.end(), {c, c + u, c + u + v, c + v});
  p.normals.insert(p.normals.end(), {n, n, n, n});
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

constexpr float kRoughness = 0.5f;
const glm::vec3 kBase(0.6f);
const glm::vec3 kEmission(0.5f);

// A closed 2 m cube facing inwards, every face the same glossy emitter.
engine::SceneAsset furnace_room() {
  engine::SceneAsset a;
  a.materials.push_back(engine::Material{
      .name = "glossy_emitter", .base_color = glm::vec4(kBase, 1.0f), .roughness = kRoughness, .emissive = kEmission});
  engine::Mesh m;
  m.name = "room";
  engine::Primitive p;
  const float s = 2.0f, h = 1.0f;
  add_quad(p, {-h, -h, -h}, {0, 0, s}, {s, 0, 0});  // floor, +y
  add_quad(p, {-h, h, -h}, {s, 0, 0}, {0, 0, s});
  add_quad(p, {-h, -h, -h}, {s, 0, 0}, {0, s, 0});
  add_quad(p, {-h, -h, h}, {0, s, 0}, {s, 0, 0});
  add_quad(p, {-h, -h, -h}, {0, s, 0}, {0, 0, s});
  add_quad(p, {h, -h, -h}, {0, 0, s}, {0, s, 0});
  p.material = 0;
  m.primitives.push_back(std::move(p));
  a.meshes.push_back(std::move(m));
  a.nodes.push_back(engine::Node{.name = "room", .mesh = 0, .gi = {engine::Mobility::Static}});
  return a;
}

// The glTF BRDF's directional albedo (diffuse + specular) at n.v = cos_v by dense quadrature.
double directional_albedo(const engine::GltfBrdf& m, float cos_v) {
  const glm::vec3 n(0, 0, 1), v(std::sqrt(1.0f - cos_v * cos_v), 0.0f, cos_v);
  constexpr int kTheta = 512, kPhi = 512;
  double sum = 0.0;
  for (int i = 0; i < kTheta; ++i) {
    // cos theta = u^2 (dense at the horizon, where grazing lobes sit); dw = 2u du dphi.
    const double u = (i + 0.5) / kTheta, c = u * u, s = std::sqrt(1.0 - c * c);
    for (int j = 0; j < kPhi; ++j) {
      const double phi = 2.0 * std::numbers::pi * (j + 0.5) / kPhi;
      const glm::vec3 l(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                        static_cast<float>(c));
      sum += static_cast<double>(engine::gltf_eval_cos(m, n, v, l).sum().y) * 2.0 * u;
    }
  }
  return sum * (1.0 / kTheta) * (2.0 * std::numbers::pi / kPhi);
}

TEST(DlmFurnace, GlossyFloorReflectsItsDirectionalAlbedo) {
  const gi::BakeInput input = gi::bake_input_from(furnace_room());
  gi::DlmSettings st;
  st.texels_per_metre = 2.0f;
  st.photons = 1'000'000;
  st.splat_radius_texels = 1.5f;
  st.area_light_samples = 4;
  st.glossy_roughness = 0.8f;
  auto dlm = gi::bake_dlm(input, st);
  ASSERT_TRUE(dlm) << dlm.error().to_string();
  const engine::GltfBrdf m = engine::gltf_brdf(kBase, 0.0f, kRoughness);
  const float a = engine::gltf_hemispherical_albedo(m).sum().y;
  const double l_in = static_cast<double>(kEmission.y * a / (1.0f - a));
  // The floor's texels (normal +y), gutter texels excluded.
  const glm::vec3 n(0, 1, 0);
  const auto rast = gi::rasterize_atlas(dlm->layout, gi::atlas_inputs_from(input));
  std::vector<std::size_t> floor;
  for (std::size_t i = 0; i < dlm->texels.size(); ++i)
    if (const std::uint32_t t = dlm->texels[i]; rast.valid[t] && rast.normal[t].y > 0.99f) floor.push_back(i);
  ASSERT_GT(floor.size(), 8u);
  for (const float cos_v : {1.0f, 0.7f, 0.4f, 0.2f, 0.1f}) {
    double sum = 0.0;
    for (const float azimuth : {0.0f, 0.8f, 1.6f, 2.4f, 3.2f, 4.0f, 4.8f, 5.6f}) {
      const float sin_v = std::sqrt(1.0f - cos_v * cos_v);
      const glm::vec3 v(sin_v * std::cos(azimuth), cos_v, sin_v * std::sin(azimuth));
      const engine::GltfBrdfValue albedo = engine::gltf_directional_albedo(m, cos_v);
      for (const std::size_t i : floor) {
        std::vector<glm::vec3> bins(dlm->directions.size());
        for (std::size_t k = 0; k < bins.size(); ++k) {
          const float* r = &dlm->radiance[(k * dlm->texels.size() + i) * 3];
          bins[k] = glm::vec3(r[0], r[1], r[2]);
        }
        const double diffuse = l_in * static_cast<double>(albedo.diffuse.y);  // E / pi x albedo_diffuse, E = pi L
        const double specular = engine::directional_specular(m, n, v, dlm->directions, bins).y;
        sum += diffuse + specular;
      }
    }
    const double rendered = sum / static_cast<double>(floor.size() * 8);
    const double expected = l_in * directional_albedo(m, cos_v);
    std::printf("furnace, cos_v %.1f: rendered %.5f, L x directional albedo %.5f (%+.2f%%)\n",
                static_cast<double>(cos_v), rendered, expected, 100.0 * (rendered / expected - 1.0));
    EXPECT_NEAR(rendered, expected, 0.02 * expected) << cos_v;
  }
}

}  // namespace
