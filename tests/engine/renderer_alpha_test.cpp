// Materials as artists make them (issue 33) on the GPU: alpha MASK / BLEND / OPAQUE in the
// forward pass and in the shadow maps, samplers, the TEXCOORD set a texture reads,
// KHR_texture_transform and tangent-space normal maps. Each test compares against the same
// scene with the feature off or against a CPU reference, so it fails if the feature does not
// act (llvmpipe, never skipped).
#include <array>
#include <cmath>
#include <cstdio>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

/// `w` x 1 RGBA8 image from per-texel {r, g, b, a}.
engine::Image row_image(std::initializer_list<std::array<std::uint8_t, 4>> texels) {
  engine::Image img;
  img.width = static_cast<int>(texels.size());
  img.height = 1;
  for (const auto& t : texels) img.rgba8.insert(img.rgba8.end(), t.begin(), t.end());
  return img;
}

/// Nearest, no mipmaps: a texel's edge is exactly where the test expects it.
engine::TextureSampler nearest(engine::TextureWrap wrap = engine::TextureWrap::ClampToEdge) {
  engine::TextureSampler s;
  s.wrap_s = s.wrap_t = wrap;
  s.mag_linear = s.min_linear = s.mipmaps = false;
  return s;
}

float channel(const engine::ImageRgbaF& img, glm::ivec2 p, int c) {
  return img
      .pixels[(static_cast<std::size_t>(p.y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(p.x)) *
                  4 +
              static_cast<std::size_t>(c)];
}

// --- Alpha: a 1 m quad at y = 2 over a floor, a point light at (-3, 4, 0): the quad's shadow
// falls on x in [2, 4], z in [-1, 1] (twice its size), away from where the camera (straight
// down from (3, 10, 0)) sees the quad itself. The quad's texture has alpha 0 on its left half
// (u < 0.5, which is z < 0 on the quad, z < 0 in its shadow).
struct ShadowScene {
  engine::SceneAsset assets;
  engine::Registry reg;
  TestCamera cam{{3.0f, 10.0f, 0.0f}, {3.0f, 0.0f, 0.0f}, 0.8f, 129};

  engine::ImageRgbaF render(engine::AlphaMode mode, glm::vec4 quad_color = {1, 0, 0, 1}, bool cut_left = true) {
    assets.images.push_back(cut_left ? row_image({{255, 255, 255, 0}, {255, 255, 255, 255}})
                                     : row_image({{255, 255, 255, 255}, {255, 255, 255, 255}}));
    assets.materials.push_back(diffuse_material(0.5f));  // floor
    engine::Material quad = diffuse_material(1.0f);
    quad.base_color = quad_color;
    quad.base_color_texture.image = 0;
    quad.base_color_texture.sampler = nearest();
    quad.alpha_mode = mode;
    quad.double_sided = true;
    assets.materials.push_back(quad);
    assets.meshes.push_back(plane_mesh(20.0f, 0));
    assets.meshes.push_back(plane_mesh(0.5f, 1));
    add_mesh(reg, 0, glm::mat4(1.0f));
    add_mesh(reg, 1, glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 2.0f, 0.0f)));
    add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 40.0f}, {-3, 4, 0}, {0, 0, 0});
    engine::Entity camera = cam.add_to(reg);
    auto r = make_renderer(assets, cam.size, 0.0f);
    if (!r) return {};
    r->render(reg, camera);
    return r->read_hdr();
  }

  /// Fraction of the floor pixels inside the shadow's square that are lit (above half the
  /// unshadowed radiance there), for z < 0 and z > 0; 0.2 m from the shadow's edges and its
  /// middle line, past the shadow filter's penumbra (~3.5 cm cube-map texels there).
  std::pair<float, float> lit_fraction(const engine::ImageRgbaF& img) const {
    int lit[2] = {0, 0}, total[2] = {0, 0};
    for (int y = 0; y < cam.size; ++y)
      for (int x = 0; x < cam.size; ++x) {
        const glm::vec3 p = cam.plane_point(x, y);
        if (p.x < 2.2f || p.x > 3.8f || std::abs(p.z) > 0.8f || std::abs(p.z) < 0.2f) continue;
        const float unshadowed = reference_point_light(0.5f, 1.0f, p, cam.eye, {-3, 4, 0}, 40.0f);
        const int side = p.z < 0.0f ? 0 : 1;
        ++total[side];
        if (red(img, x, y) > 0.5f * unshadowed) ++lit[side];
      }
    return {static_cast<float>(lit[0]) / static_cast<float>(std::max(total[0], 1)),
            static_cast<float>(lit[1]) / static_cast<float>(std::max(total[1], 1))};
  }
};

TEST(RendererAlpha, MaskCastsAShadowOnlyWhereAlphaIsAboveTheCutoff) {
  engine::GpuContext ctx = headless_context();
  ShadowScene s;
  const auto [left, right] = s.lit_fraction(s.render(engine::AlphaMode::Mask));
  std::printf("MASK: lit fraction of the shadow's z < 0 half %.3f, z > 0 half %.3f\n", static_cast<double>(left),
              static_cast<double>(right));
  EXPECT_GT(left, 0.97f) << "the cut-out half lets the light through";
  EXPECT_LT(right, 0.03f) << "the opaque half casts its shadow";
}

TEST(RendererAlpha, OpaqueIgnoresAlphaAndCastsTheWholeShadow) {
  engine::GpuContext ctx = headless_context();
  ShadowScene s;
  const auto [left, right] = s.lit_fraction(s.render(engine::AlphaMode::Opaque));
  std::printf("OPAQUE: lit fraction of the shadow's z < 0 half %.3f, z > 0 half %.3f\n", static_cast<double>(left),
              static_cast<double>(right));
  EXPECT_LT(left, 0.03f);
  EXPECT_LT(right, 0.03f);
}

TEST(RendererAlpha, BlendCastsACutOutShadowAtOneHalf) {
  engine::GpuContext ctx = headless_context();
  ShadowScene s;
  const auto [left, right] = s.lit_fraction(s.render(engine::AlphaMode::Blend));
  std::printf("BLEND: lit fraction of the shadow's z < 0 half %.3f, z > 0 half %.3f\n", static_cast<double>(left),
              static_cast<double>(right));
  EXPECT_GT(left, 0.97f);
  EXPECT_LT(right, 0.03f);
}

TEST(RendererAlpha, MaskIsDiscardedInTheForwardPass) {
  engine::GpuContext ctx = headless_context();
  ShadowScene s;
  const engine::ImageRgbaF img = s.render(engine::AlphaMode::Mask);
  // The quad is red (green 0); the grey floor seen through its cut-out half has green > 0.
  const glm::ivec2 cut = s.cam.pixel_of({0.0f, 2.0f, -0.25f});
  const glm::ivec2 kept = s.cam.pixel_of({0.0f, 2.0f, 0.25f});
  EXPECT_GT(channel(img, cut, 1), 0.05f) << "the floor shows through the cut-out half";
  EXPECT_NEAR(channel(img, cut, 0), channel(img, cut, 1), 1e-3f) << "grey floor, not the red quad";
  // The kept half is the red quad: only its white specular layer (F0 0.04) is not red.
  EXPECT_GT(channel(img, kept, 0), 0.05f);
  EXPECT_LT(channel(img, kept, 1), 0.1f * channel(img, kept, 0));
}

TEST(RendererAlpha, BlendAtOneHalfMixesWithWhatIsBehind) {
  engine::GpuContext ctx = headless_context();
  const glm::vec3 at(0.0f, 2.0f, 0.25f);
  ShadowScene opaque;
  const engine::ImageRgbaF quad = opaque.render(engine::AlphaMode::Opaque, {1, 0, 0, 1}, false);
  ShadowScene cut;  // the floor behind the same pixel: the quad's left half cut away there too
  const engine::ImageRgbaF floor = cut.render(engine::AlphaMode::Mask, {1, 0, 0, 0}, false);
  ShadowScene blend;
  const engine::ImageRgbaF mixed = blend.render(engine::AlphaMode::Blend, {1, 0, 0, 0.5f}, false);
  const glm::ivec2 p = blend.cam.pixel_of(at);
  for (int c : {0, 1}) {
    const float expected = 0.5f * channel(quad, p, c) + 0.5f * channel(floor, p, c);
    std::printf("BLEND 50%%: channel %d %.4f, 0.5 quad + 0.5 floor %.4f\n", c,
                static_cast<double>(channel(mixed, p, c)), static_cast<double>(expected));
    EXPECT_NEAR(channel(mixed, p, c), expected, 0.02f * expected + 1e-4f) << "channel " << c;
  }
  EXPECT_GT(channel(floor, p, 1), 0.05f);  // the mix is not trivially one of the two
  EXPECT_GT(channel(quad, p, 0), 2.0f * channel(floor, p, 0));
}

// --- Texturing: an emissive quad of 2 m at y = 0 seen from above (base colour black, so the
// radiance is the emissive texture's texel: 0 or 1). u runs along +z, v along +x.
struct EmissiveQuad {
  engine::SceneAsset assets;
  engine::Registry reg;
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.8f, 129};
  engine::Material material = [] {
    engine::Material m = diffuse_material(0.0f);
    m.emissive = glm::vec3(1.0f);
    m.emissive_texture.image = 0;
    m.emissive_texture.sampler = nearest();
    return m;
  }();

  engine::ImageRgbaF render(float uv0_scale = 1.0f, bool zero_uv0 = false) {
    assets.images.push_back(row_image({{0, 0, 0, 255}, {255, 255, 255, 255}}));  // black | white
    assets.materials.push_back(material);
    engine::Mesh m = plane_mesh(1.0f, 0);
    for (glm::vec2& uv : m.primitives[0].uv0) uv = zero_uv0 ? glm::vec2(0.0f) : uv * uv0_scale;
    assets.meshes.push_back(m);
    add_mesh(reg, 0, glm::mat4(1.0f));
    engine::Entity camera = cam.add_to(reg);
    auto r = make_renderer(assets, cam.size, 0.0f);
    if (!r) return {};
    r->render(reg, camera);
    return r->read_hdr();
  }
  /// Radiance where the quad's unscaled UV is (u, v).
  float at(const engine::ImageRgbaF& img, float u, float v) const {
    return red(img, cam.pixel_of({2.0f * v - 1.0f, 0.0f, 2.0f * u - 1.0f}));
  }
};

TEST(RendererTextures, ClampAndRepeatDifferBeyondOne) {
  engine::GpuContext ctx = headless_context();
  // uv0 x 2: at the quad's u = 0.65 the texture is read at 1.3: REPEAT reads 0.3 (black),
  // CLAMP_TO_EDGE the last texel (white).
  EmissiveQuad repeat;
  repeat.material.emissive_texture.sampler = nearest(engine::TextureWrap::Repeat);
  const engine::ImageRgbaF r = repeat.render(2.0f);
  EmissiveQuad clamp;
  const engine::ImageRgbaF c = clamp.render(2.0f);
  EXPECT_LT(repeat.at(r, 0.65f, 0.5f), 0.01f);
  EXPECT_GT(clamp.at(c, 0.65f, 0.5f), 0.99f);
  EmissiveQuad mirrored;  // MIRRORED_REPEAT reads 0.7 there: white
  mirrored.material.emissive_texture.sampler = nearest(engine::TextureWrap::MirroredRepeat);
  const engine::ImageRgbaF m = mirrored.render(2.0f);
  EXPECT_GT(mirrored.at(m, 0.65f, 0.5f), 0.99f);
  // Inside [0, 1] the three agree: u = 0.15 reads 0.3 (black).
  EXPECT_LT(repeat.at(r, 0.15f, 0.5f), 0.01f);
  EXPECT_LT(clamp.at(c, 0.15f, 0.5f), 0.01f);
}

TEST(RendererTextures, TexCoordOneReadsUv1) {
  engine::GpuContext ctx = headless_context();
  EmissiveQuad set0;  // uv0 is all zero: TEXCOORD_0 reads the black texel everywhere
  const engine::ImageRgbaF a = set0.render(1.0f, true);
  EmissiveQuad set1;
  set1.material.emissive_texture.texcoord = 1;
  const engine::ImageRgbaF b = set1.render(1.0f, true);
  EXPECT_LT(set0.at(a, 0.75f, 0.5f), 0.01f);
  EXPECT_GT(set1.at(b, 0.75f, 0.5f), 0.99f);
  EXPECT_LT(set1.at(b, 0.25f, 0.5f), 0.01f);
}

TEST(RendererTextures, TextureTransformOffsetScaleAndRotationMoveTheTexture) {
  engine::GpuContext ctx = headless_context();
  EmissiveQuad plain;
  const engine::ImageRgbaF p = plain.render();
  EXPECT_LT(plain.at(p, 0.25f, 0.75f), 0.01f);
  EXPECT_GT(plain.at(p, 0.75f, 0.25f), 0.99f);

  EmissiveQuad offset;  // u + 0.5: u = 0.25 reads 0.75 (white)
  offset.material.emissive_texture.transform.offset = {0.5f, 0.0f};
  const engine::ImageRgbaF o = offset.render();
  EXPECT_GT(offset.at(o, 0.25f, 0.75f), 0.99f);

  EmissiveQuad scale;  // u x 0.5: u = 0.75 reads 0.375 (black)
  scale.material.emissive_texture.transform.scale = {0.5f, 1.0f};
  const engine::ImageRgbaF s = scale.render();
  EXPECT_LT(scale.at(s, 0.75f, 0.25f), 0.01f);

  // Rotation pi/2 (counter-clockwise on the image, v down): u' = v, v' = -u. At (u, v) =
  // (0.25, 0.75) it reads u' = 0.75 (white); the opposite sign would read u' = -0.75 (black).
  EmissiveQuad rotated;
  rotated.material.emissive_texture.transform.rotation_rad = 1.57079632679f;
  const engine::ImageRgbaF rr = rotated.render();
  EXPECT_GT(rotated.at(rr, 0.25f, 0.75f), 0.99f);
  EXPECT_LT(rotated.at(rr, 0.75f, 0.25f), 0.01f);
  EXPECT_NEAR(engine::transformed_uv(rotated.material.emissive_texture.transform, {0.25f, 0.75f}).x, 0.75f, 1e-6f);
}

// --- Normal maps: a plane lit by a directional light from 45 degrees toward +z, seen from
// straight above; its normal map tilts every normal 45 degrees toward +u (= +z, the generated
// tangent): the tilted normal faces the light (cos 1 instead of cos 45).
struct NormalMappedPlane {
  engine::SceneAsset assets;
  engine::Registry reg;
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.8f, 65};

  engine::ImageRgbaF render(bool normal_map, float scale = 1.0f, glm::vec3 light_from = {0.0f, 1.0f, 1.0f}) {
    assets.images.push_back(row_image({{218, 128, 218, 255}}));  // n_t ~ (0.71, 0, 0.71)
    engine::Material m = diffuse_material(0.5f);
    if (normal_map) {
      m.normal_texture.image = 0;
      m.normal_scale = scale;
    }
    assets.materials.push_back(m);
    assets.meshes.push_back(plane_mesh(5.0f, 0));
    add_mesh(reg, 0, glm::mat4(1.0f));
    add_light(reg, engine::Light{.type = engine::LightType::Directional, .intensity = 3.0f}, light_from, {0, 0, 0});
    engine::Entity camera = cam.add_to(reg);
    auto r = make_renderer(assets, cam.size, 0.0f);
    if (!r) return {};
    r->render(reg, camera);
    return r->read_hdr();
  }
};

/// The normal the shader reconstructs from texel (218, 128, 218) with `scale` in the frame
/// T = +z, B = cross(N, T) = +x... (w = +1), N = +y.
glm::vec3 tilted_normal(float scale) {
  const glm::vec3 tn((2.0f * 218.0f / 255.0f - 1.0f) * scale, (2.0f * 128.0f / 255.0f - 1.0f) * scale,
                     2.0f * 218.0f / 255.0f - 1.0f);
  const glm::vec3 t(0, 0, 1), n(0, 1, 0), b = glm::cross(n, t);
  return glm::normalize(tn.x * t + tn.y * b + tn.z * n);
}

TEST(RendererNormalMap, TiltedNormalMapShadesWithTheTiltedNormal) {
  engine::GpuContext ctx = headless_context();
  NormalMappedPlane flat;
  const engine::ImageRgbaF a = flat.render(false);
  NormalMappedPlane mapped;
  const engine::ImageRgbaF b = mapped.render(true);
  const int c = flat.cam.size / 2;
  const glm::vec3 v(0, 1, 0), l = glm::normalize(glm::vec3(0, 1, 1));
  const float expected_ratio = reference_brdf_cos(0.5f, 0.0f, 1.0f, tilted_normal(1.0f), v, l) /
                               reference_brdf_cos(0.5f, 0.0f, 1.0f, glm::vec3(0, 1, 0), v, l);
  ASSERT_GT(red(a, c, c), 0.0f);
  EXPECT_GT(expected_ratio, 1.3f);  // cos 0 / cos 45 for the diffuse part
  std::printf("normal map: radiance ratio %.4f, reference %.4f\n", static_cast<double>(red(b, c, c) / red(a, c, c)),
              static_cast<double>(expected_ratio));
  EXPECT_NEAR(red(b, c, c) / red(a, c, c), expected_ratio, 0.02f * expected_ratio);
}

TEST(RendererNormalMap, ScaleZeroIsTheVertexNormalAndTheTiltFollowsTheTangent) {
  engine::GpuContext ctx = headless_context();
  NormalMappedPlane flat;
  const engine::ImageRgbaF a = flat.render(false, 1.0f, {0.0f, 1.0f, -1.0f});
  NormalMappedPlane zero;
  const engine::ImageRgbaF z = zero.render(true, 0.0f, {0.0f, 1.0f, -1.0f});
  NormalMappedPlane away;  // light from -z: the normal tilted toward +z turns away from it
  const engine::ImageRgbaF w = away.render(true, 1.0f, {0.0f, 1.0f, -1.0f});
  const int c = flat.cam.size / 2;
  EXPECT_NEAR(red(z, c, c), red(a, c, c), 1e-3f * red(a, c, c));
  EXPECT_LT(red(w, c, c), 0.1f * red(a, c, c));  // n.l = cos 90 for the tilted normal
}

}  // namespace
