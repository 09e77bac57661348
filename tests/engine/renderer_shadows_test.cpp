// Shadows, split view, indirect-light plumbing and the LDR encoding of the renderer.
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <engine/gltf_brdf.h>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr float kAlbedo = 0.5f;
constexpr float kAmbient = 0.05f;  // stand-in ambient radiance, W/(m^2 sr)

// A plane, a 0.3 m box floating at (-0.75, 1, 0) and a light at (-1.5, 2, 0) aimed at the
// origin: the box's shadow is centred on the origin, which the camera above sees.
struct OccluderScene {
  engine::SceneAsset assets;
  engine::Registry reg;
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};

  OccluderScene() {
    assets.materials.push_back(diffuse_material(kAlbedo));
    assets.meshes.push_back(plane_mesh(10.0f, 0));
    assets.meshes.push_back(box_mesh(glm::vec3(0.15f), 0));
    add_mesh(reg, 0, glm::mat4(1.0f));
    add_mesh(reg, 1, glm::translate(glm::mat4(1.0f), glm::vec3(-0.75f, 1.0f, 0.0f)));
  }
  engine::ImageRgbaF render(const engine::Light& light) {
    add_light(reg, light, {-1.5f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f});
    engine::Entity camera = cam.add_to(reg);
    auto r = make_renderer(assets, cam.size, kAmbient);
    if (!r) return {};
    r->render(reg, camera);
    EXPECT_EQ(r->last_timings().size(), 3u);
    return r->read_hdr();
  }
};

// The pixel at the centre of the box's shadow sees only the ambient term; a pixel beside
// the shadow is lit: at least 4x the ambient term.
void expect_shadow(const engine::ImageRgbaF& img, const TestCamera& cam) {
  ASSERT_EQ(img.width, cam.size);
  const float ambient_only = kAlbedo * kAmbient;  // albedo/pi * (pi * L_ambient)
  const float shadowed = red(img, cam.pixel_of({0.0f, 0.0f, 0.0f}));
  const float beside = red(img, cam.pixel_of({0.0f, 0.0f, 0.8f}));
  EXPECT_NEAR(shadowed, ambient_only, 0.05f * ambient_only) << "centre of the box's shadow";
  EXPECT_GT(beside, 4.0f * ambient_only) << "beside the shadow";
}

TEST(RendererShadows, PointLightCubeMapShadow) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  expect_shadow(s.render(engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}), s.cam);
}

// RenderSettings::flat_shading, the frame's yardstick for tools/perf-report.sh: every surface
// shows its base colour unlit, in and beside the shadow, and the full frame comes back after.
TEST(RendererShadows, FlatShadingYardstickWritesTheBaseColourUnlit) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  add_light(s.reg, engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}, {-1.5f, 2.0f, 0.0f}, {0, 0, 0});
  engine::Entity camera = s.cam.add_to(s.reg);
  auto r = make_renderer(s.assets, s.cam.size, kAmbient);
  ASSERT_NE(r, nullptr);
  const glm::ivec2 in_shadow = s.cam.pixel_of({0.0f, 0.0f, 0.0f}), beside = s.cam.pixel_of({0.0f, 0.0f, 0.8f});
  r->settings().flat_shading = true;
  r->render(s.reg, camera);
  engine::ImageRgbaF img = r->read_hdr();
  EXPECT_NEAR(red(img, in_shadow), kAlbedo, 1e-4f);
  EXPECT_NEAR(red(img, beside), kAlbedo, 1e-4f);
  r->settings().flat_shading = false;
  r->render(s.reg, camera);
  img = r->read_hdr();
  expect_shadow(img, s.cam);
}

TEST(RendererShadows, SpotLightShadow) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  expect_shadow(s.render(engine::Light{.type = engine::LightType::Spot, .intensity = 10.0f, .outer_cone_rad = 0.7f}),
                s.cam);
}

TEST(RendererShadows, DirectionalLightShadow) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  expect_shadow(s.render(engine::Light{.type = engine::LightType::Directional, .intensity = 3.0f}), s.cam);
}

TEST(RendererShadows, AreaLightShadow) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  expect_shadow(
      s.render(engine::Light{.type = engine::LightType::Area, .intensity = 250.0f, .area_size_m = {0.2f, 0.2f}}),
      s.cam);
}

TEST(RendererShadows, NoSelfShadowAcneOnLitPlane) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  const engine::ImageRgbaF img = s.render(engine::Light{.type = engine::LightType::Point, .intensity = 10.0f});
  // Every pixel of the lit plane away from the shadow matches the unshadowed reference.
  int checked = 0;
  for (int y = 0; y < s.cam.size; y += 4)
    for (int x = 0; x < s.cam.size; x += 4) {
      const glm::vec3 p = s.cam.plane_point(x, y);
      if (p.x < 0.8f && std::abs(p.z) < 0.45f) continue;  // the box's shadow spans x in [-0.4, 0.62] m
      const float expected =
          reference_point_light(kAlbedo, 1.0f, p, s.cam.eye, {-1.5f, 2.0f, 0.0f}, 10.0f) + kAlbedo * kAmbient;
      EXPECT_NEAR(red(img, x, y), expected, 0.02f * expected) << "pixel " << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(RendererSplitView, LeftHalfDirectOnlyRightHalfAddsAmbient) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(kAlbedo));
  assets.meshes.push_back(plane_mesh(10.0f, 0));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}, {0, 2, 0}, {0, 0, 0});
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, cam.size, 0.2f);
  ASSERT_NE(r, nullptr);
  r->settings().split = engine::SplitView::DirectLeftFullRight;
  r->render(reg, camera);
  const engine::ImageRgbaF img = r->read_hdr();
  const int c = cam.size / 2;
  // Mirror-symmetric pixels: same direct light, the right one adds albedo * L_ambient.
  const float left = red(img, c - 10, c);
  const float right = red(img, c + 10, c);
  EXPECT_LT(left, right);
  EXPECT_NEAR(right - left, kAlbedo * 0.2f, 0.02f * kAlbedo * 0.2f);
  EXPECT_NE(r->last_timings()[1].name.find("constant ambient (stand-in)"), std::string::npos);
}

// sRGB(ACES fitted (Narkowicz 2015)(x * exposure)), written independently of the shader.
float expected_ldr(float linear) {
  const float x = linear;
  const float t = std::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
  const float s = t <= 0.0031308f ? 12.92f * t : 1.055f * std::pow(t, 1.0f / 2.4f) - 0.055f;
  return s * 255.0f;
}

TEST(RendererTonemap, LdrPixelIsTonemappedHdrPixel) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(kAlbedo));
  assets.meshes.push_back(plane_mesh(10.0f, 0));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}, {0, 2, 0}, {0, 0, 0});
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  r->settings().exposure = 0.7f;
  r->render(reg, camera);
  const engine::ImageRgbaF hdr = r->read_hdr();
  const engine::ImageRgba8 ldr = r->read_ldr();
  ASSERT_EQ(ldr.width, cam.size);
  ASSERT_EQ(ldr.height, cam.size);
  for (glm::ivec2 p : {glm::ivec2(cam.size / 2, cam.size / 2), glm::ivec2(3, 5), glm::ivec2(cam.size - 2, 10)}) {
    const float expected = expected_ldr(red(hdr, p) * 0.7f);
    const auto got = static_cast<float>(ldr.pixels[(static_cast<std::size_t>(p.y) * cam.size + p.x) * 4]);
    EXPECT_NEAR(got, expected, 1.0f) << "pixel " << p.x << "," << p.y;
    EXPECT_EQ(ldr.pixels[(static_cast<std::size_t>(p.y) * cam.size + p.x) * 4 + 3], 255);
  }
}

TEST(RendererReadback, RowsRunTopToBottom) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(kAlbedo));
  assets.meshes.push_back(plane_mesh(10.0f, 0));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  // The camera's up is world -Z: a light at z = -1 is near the top of the image.
  add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}, {0, 1, -1}, {0, 0, -1});
  engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  r->render(reg, camera);
  const engine::ImageRgbaF hdr = r->read_hdr();
  const glm::ivec2 under = cam.pixel_of({0, 0, -1});
  EXPECT_LT(under.y, cam.size / 2);
  EXPECT_GT(red(hdr, cam.size / 2, 2), red(hdr, cam.size / 2, cam.size - 3));
  const float expected =
      reference_point_light(kAlbedo, 1.0f, cam.plane_point(under.x, under.y), cam.eye, {0, 1, -1}, 10.0f);
  EXPECT_NEAR(red(hdr, under), expected, 0.02f * expected);
}

// A provider with a constant 1x1 irradiance atlas and a per-vertex buffer for one entity.
class ConstantIndirect : public engine::IndirectLightProvider {
 public:
  struct Frame : engine::IndirectLightFrame {
    engine::Entity dynamic;
    std::uint32_t buffer = 0;
    engine::SsboHandle<engine::VertexIrradiance> vertex_irradiance_buffer(engine::Entity e) const override {
      return {e == dynamic ? buffer : 0};
    }
  };
  const engine::IndirectLightFrame& frame() override { return frame_; }
  const char* label() const override { return "test constant"; }
  Frame frame_;
};

TEST(RendererIndirect, AtlasForStaticAndVertexBufferForDynamicMeshes) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(kAlbedo));
  assets.meshes.push_back(plane_mesh(1.0f, 0));
  engine::Registry reg;
  add_mesh(reg, 0, glm::translate(glm::mat4(1.0f), glm::vec3(-1.2f, 0, 0)), /*is_static=*/true);
  engine::Entity dyn = add_mesh(reg, 0, glm::translate(glm::mat4(1.0f), glm::vec3(1.2f, 0, 0)), /*is_static=*/false);
  TestCamera cam{{0.0f, 4.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  engine::Entity camera = cam.add_to(reg);

  const float atlas_e = 2.0f;  // W/m^2
  const float atlas_texel[4] = {atlas_e, atlas_e, atlas_e, 1.0f};
  GLuint atlas = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &atlas);
  glTextureStorage2D(atlas, 1, GL_RGBA32F, 1, 1);
  glTextureSubImage2D(atlas, 0, 0, 0, 1, 1, GL_RGBA, GL_FLOAT, atlas_texel);
  // Per-vertex irradiance of the dynamic plane's 4 vertices: 4 W/m^2 everywhere.
  const float vertex_e[16] = {4, 4, 4, 0, 4, 4, 4, 0, 4, 4, 4, 0, 4, 4, 4, 0};
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  glNamedBufferStorage(buffer, sizeof vertex_e, vertex_e, 0);

  ConstantIndirect provider;
  provider.frame_.irradiance_atlas_texture = {atlas};
  provider.frame_.dynamic = dyn;
  provider.frame_.buffer = buffer;
  {
    auto r = make_renderer(assets, cam.size, 0.3f);
    ASSERT_NE(r, nullptr);
    r->set_indirect_light(&provider);
    r->render(reg, camera);
    const engine::ImageRgbaF img = r->read_hdr();
    // Irradiance without direction is reflected as uniform light: E / pi x the BRDF's
    // directional albedo at the view angle (both lobes).
    const float cos_v = 4.0f / std::sqrt(16.0f + 1.2f * 1.2f);
    const float albedo =
        engine::gltf_directional_albedo(engine::gltf_brdf(glm::vec3(kAlbedo), 0.0f, 1.0f), cos_v).sum().x;
    EXPECT_NEAR(red(img, cam.pixel_of({-1.2f, 0, 0})), albedo / kPi * atlas_e, 0.01f * albedo / kPi * atlas_e);
    EXPECT_NEAR(red(img, cam.pixel_of({1.2f, 0, 0})), albedo / kPi * 4.0f, 0.01f * albedo / kPi * 4.0f);
    ASSERT_EQ(r->last_timings().size(), 4u);
    EXPECT_NE(r->last_timings()[1].name.find("indirect light update (test constant"), std::string::npos);
    EXPECT_NE(r->last_timings()[2].name.find("forward + indirect (test constant"), std::string::npos);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  }
  glDeleteTextures(1, &atlas);
  glDeleteBuffers(1, &buffer);
}

}  // namespace

namespace {

bool same_pixels(const engine::ImageRgbaF& a, const engine::ImageRgbaF& b) {
  return a.width == b.width && a.height == b.height && a.pixels == b.pixels;
}

// The last frame of `r` equals what a fresh renderer draws of the same registry: every
// shadow view drawn from scratch.
void expect_same_as_fresh(engine::Renderer& r, OccluderScene& s, engine::Entity camera, const char* what) {
  const engine::ImageRgbaF img = r.read_hdr();
  auto fresh = make_renderer(s.assets, s.cam.size, kAmbient);
  ASSERT_TRUE(fresh);
  fresh->render(s.reg, camera);
  EXPECT_TRUE(same_pixels(img, fresh->read_hdr())) << what;
}

// The two lights of the shadow-map caching tests: a spot (a 2-D map) and a point light (6 cube faces).
void add_spot_and_point(engine::Registry& reg) {
  add_light(reg, engine::Light{.type = engine::LightType::Spot, .intensity = 10.0f, .outer_cone_rad = 0.7f},
            {-1.5f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f});
  add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 5.0f}, {1.5f, 2.0f, 0.5f},
            {0.0f, 0.0f, 0.0f});
}

// Shadow maps are kept while neither their light nor a caster that can reach them moved:
// a second frame re-renders none and draws the same pixels; moving the box re-renders the
// views it can reach and draws what a fresh renderer draws; moving it back restores the
// first frame exactly. A spot (2-D map) and a point light (6 cube faces).
TEST(RendererShadows, MapsAreReRenderedOnlyWhenTheirLightOrACasterMoves) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  add_spot_and_point(s.reg);
  const engine::Entity camera = s.cam.add_to(s.reg);
  auto r = make_renderer(s.assets, s.cam.size, kAmbient);
  ASSERT_TRUE(r);
  r->render(s.reg, camera);
  EXPECT_EQ(r->last_timings().front().name, "shadow maps (7 views)");
  // The camera looks down from above the lights: cube faces it cannot see into wait.
  EXPECT_EQ(r->last_shadow_maps_rendered() + r->last_shadow_maps_unseen(), 7);
  EXPECT_GT(r->last_shadow_maps_rendered(), 0);
  const engine::ImageRgbaF first = r->read_hdr();
  r->render(s.reg, camera);
  EXPECT_EQ(r->last_shadow_maps_rendered(), 0);
  EXPECT_TRUE(same_pixels(r->read_hdr(), first));

  engine::Entity box{};
  s.reg.view<engine::MeshRenderer>().each([&](engine::Entity e, const engine::MeshRenderer& mr) {
    if (mr.mesh == 1) box = e;
  });
  ASSERT_FALSE(box.is_null());
  const glm::mat4 moved = glm::translate(glm::mat4(1.0f), glm::vec3(0.6f, 0.8f, 0.3f));
  const glm::mat4 original = s.reg.get<engine::WorldTransform>(box).matrix;
  s.reg.write<engine::WorldTransform>(box).matrix = moved;
  r->render(s.reg, camera);
  const int redrawn = r->last_shadow_maps_rendered();
  EXPECT_GT(redrawn, 0);
  const engine::ImageRgbaF after_move = r->read_hdr();
  EXPECT_FALSE(same_pixels(after_move, first));
  auto fresh = make_renderer(s.assets, s.cam.size, kAmbient);
  ASSERT_TRUE(fresh);
  fresh->render(s.reg, camera);
  EXPECT_TRUE(same_pixels(after_move, fresh->read_hdr())) << redrawn << " views redrawn";

  s.reg.write<engine::WorldTransform>(box).matrix = original;
  r->render(s.reg, camera);
  EXPECT_TRUE(same_pixels(r->read_hdr(), first));
}

// A view that changed but that the camera cannot see into is not drawn; when the camera turns
// to it, it is drawn before use: each frame equals a fresh renderer's, which draws every view
// the camera can see from scratch. The point light moves every frame (its faces always change).
TEST(RendererShadows, UnseenViewsAreDrawnWhenTheCameraTurnsToThem) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  const engine::Entity lamp = add_light(s.reg, engine::Light{.type = engine::LightType::Point, .intensity = 5.0f},
                                        {1.5f, 2.0f, 0.5f}, {0, 0, 0});
  const engine::Entity camera = s.cam.add_to(s.reg);
  auto r = make_renderer(s.assets, s.cam.size, kAmbient);
  ASSERT_TRUE(r);
  const auto matches_fresh = [&](const char* what) { expect_same_as_fresh(*r, s, camera, what); };
  // Looking straight down at the floor from 3 m: the faces above the light are out of view.
  r->render(s.reg, camera);
  EXPECT_GT(r->last_shadow_maps_unseen(), 0);
  EXPECT_EQ(r->last_shadow_maps_rendered() + r->last_shadow_maps_unseen(), 6);
  s.reg.write<engine::WorldTransform>(lamp).matrix = looking_at({1.2f, 2.1f, 0.3f}, {0, 0, 0});
  r->render(s.reg, camera);
  const int unseen = r->last_shadow_maps_unseen();
  EXPECT_GT(unseen, 0);
  matches_fresh("looking down");
  // Turned to look up past the light and the box: the faces left undrawn are drawn now.
  s.reg.write<engine::WorldTransform>(camera).matrix = looking_at({-2.0f, 0.5f, -1.0f}, {1.2f, 3.0f, 0.3f});
  r->render(s.reg, camera);
  EXPECT_LT(r->last_shadow_maps_unseen(), unseen);
  matches_fresh("turned up");
}

// A light that stays while a dynamic caster moves keeps its static casters' depth in a cache:
// the views are then a copy plus the dynamic caster alone, and every frame must equal what a
// fresh renderer (drawing every caster) draws; a static caster moving too invalidates it.
TEST(RendererShadows, StaticDepthCacheDrawsWhatDrawingEveryCasterDraws) {
  engine::GpuContext ctx = headless_context();
  OccluderScene s;
  add_spot_and_point(s.reg);
  const auto at = [](glm::vec3 p) { return glm::translate(glm::mat4(1.0f), p); };
  const engine::Entity crate = add_mesh(s.reg, 1, at({0.5f, 0.9f, 0.6f}), /*is_static=*/false);
  engine::Entity box{};
  s.reg.view<engine::MeshRenderer>().each([&](engine::Entity e, const engine::MeshRenderer& mr) {
    if (mr.mesh == 1 && e != crate) box = e;
  });
  ASSERT_FALSE(box.is_null());
  const engine::Entity camera = s.cam.add_to(s.reg);
  auto r = make_renderer(s.assets, s.cam.size, kAmbient);
  ASSERT_TRUE(r);
  const auto matches_fresh = [&](const char* what) { expect_same_as_fresh(*r, s, camera, what); };
  r->render(s.reg, camera);
  EXPECT_EQ(r->last_shadow_maps_over_static_depth(), 0);
  const engine::ImageRgbaF first = r->read_hdr();

  s.reg.write<engine::WorldTransform>(crate).matrix = at({0.2f, 0.9f, 0.9f});
  r->render(s.reg, camera);  // the lights' static depth is cached now
  EXPECT_EQ(r->last_shadow_maps_over_static_depth(), 0);
  EXPECT_FALSE(same_pixels(r->read_hdr(), first)) << "the crate's shadow moved";
  matches_fresh("first move (static depth drawn into the cache)");

  s.reg.write<engine::WorldTransform>(crate).matrix = at({-0.2f, 0.7f, 0.8f});
  r->render(s.reg, camera);
  const int cached = r->last_shadow_maps_over_static_depth();
  EXPECT_GT(cached, 0);
  EXPECT_LE(cached, r->last_shadow_maps_rendered());  // a view the crate just entered fills its cache now
  matches_fresh("second move (from the cache)");

  s.reg.write<engine::WorldTransform>(box).matrix = at({-0.5f, 1.1f, -0.2f});
  s.reg.write<engine::WorldTransform>(crate).matrix = at({0.3f, 0.8f, 0.4f});
  r->render(s.reg, camera);
  EXPECT_LT(r->last_shadow_maps_over_static_depth(), r->last_shadow_maps_rendered());
  matches_fresh("a static caster moved too (the cache is redrawn)");
}

}  // namespace

namespace {

// A square area light of side W facing down at height H, a plate at height hb covering x < 0
// and a floor: the floor point at x sees the part of the light with
// light x >= -x (H - hb) / hb, so its penumbra is a ramp W hb / (H - hb) wide (linear for a
// rectangle, up to the cos^2 / d^2 weights over it). Returns the 10-90% width of the edge
// along the image row through the origin, measured on the rendered frame.
engine::ImageRgbaF area_light_frame(bool soft, bool with_plate, float side_m, float height_m, float plate_m,
                                    const TestCamera& cam) {
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(kAlbedo));
  assets.meshes.push_back(plane_mesh(3.0f, 0));
  engine::Mesh plate;
  plate.name = "plate";
  plate.primitives.emplace_back();
  plate.primitives[0].material = 0;
  add_quad(plate.primitives[0], glm::vec3(-1.5f, plate_m, 0.0f), glm::vec3(0, 0, 1.5f), glm::vec3(1.5f, 0, 0));
  assets.meshes.push_back(plate);
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  if (with_plate) add_mesh(reg, 1, glm::mat4(1.0f));
  add_light(reg, engine::Light{.type = engine::LightType::Area, .intensity = 20.0f, .area_size_m = {side_m, side_m}},
            {0.0f, height_m, 0.0f}, {0.0f, 0.0f, 0.0f});
  const engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, cam.size, 0.0f);
  if (!r) return {};
  r->settings().shadow_map_size = 1024;
  r->settings().area_soft_shadows = soft;
  r->render(reg, camera);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  return r->read_hdr();
}

double area_edge_width(bool soft, float side_m, float height_m, float plate_m) {
  const TestCamera cam{{0.0f, 0.9f, 1.5f}, {0.0f, 0.0f, 0.0f}, 0.9f, 161};
  const engine::ImageRgbaF img = area_light_frame(soft, true, side_m, height_m, plate_m, cam);
  const engine::ImageRgbaF open = area_light_frame(soft, false, side_m, height_m, plate_m, cam);
  if (img.pixels.empty() || open.pixels.empty()) return 0.0;
  EXPECT_LT(red(img, cam.pixel_of({-0.6f, 0, 0})), 0.02f * red(open, cam.pixel_of({-0.6f, 0, 0})));
  EXPECT_NEAR(red(img, cam.pixel_of({0.6f, 0, 0})), red(open, cam.pixel_of({0.6f, 0, 0})),
              0.02f * red(open, cam.pixel_of({0.6f, 0, 0})));
  // Along the image row through the origin: x of each pixel on the floor and its lit
  // fraction (the frame with the plate over the one without).
  const glm::ivec2 centre = cam.pixel_of({0, 0, 0});
  double x10 = 0.0, x90 = 0.0, prev_x = -1.0, prev_f = 0.0;
  for (int px = 0; px < cam.size; ++px) {
    const double x = static_cast<double>(cam.plane_point(px, centre.y).x);
    const double f = static_cast<double>(red(img, px, centre.y) / std::max(red(open, px, centre.y), 1e-6f));
    if (px > 0 && prev_f < 0.1 && f >= 0.1) x10 = prev_x + (0.1 - prev_f) / (f - prev_f) * (x - prev_x);
    if (px > 0 && prev_f < 0.9 && f >= 0.9) x90 = prev_x + (0.9 - prev_f) / (f - prev_f) * (x - prev_x);
    prev_x = x;
    prev_f = f;
  }
  return x90 - x10;
}

}  // namespace

// RenderSettings::area_soft_shadows: the penumbra of an area light follows its size (a 0.6 m
// light 2 m up, a plate 1 m up: a 0.6 m ramp, 0.48 m from 10% to 90%), where the shadow seen
// from the light's centre alone is a few texels wide.
TEST(RendererShadows, AreaLightPenumbraFollowsTheLightsSize) {
  engine::GpuContext ctx = headless_context();
  const double ramp = 0.6 * 1.0 / (2.0 - 1.0);
  const double soft = area_edge_width(true, 0.6f, 2.0f, 1.0f);
  const double hard = area_edge_width(false, 0.6f, 2.0f, 1.0f);
  std::printf(
      "area light 0.6 m, 10-90%% shadow edge: soft %.4f m, from the centre %.4f m (geometry 0.8 x %.3f = %.4f)\n", soft,
      hard, ramp, 0.8 * ramp);
  EXPECT_NEAR(soft, 0.8 * ramp, 0.2 * 0.8 * ramp);
  EXPECT_LT(hard, 0.25 * soft);
}
