// Reflection probes in the forward pass (engine/indirect_light.h, reflection_probe_*;
// engine/shaders/reflection_probes.glsl), on llvmpipe: a glossy floor in a 4 x 3 x 4 m room
// whose +X wall is bright shows the wall's reflection exactly where the mirror geometry of
// the room's box puts it (not where an infinitely distant cube map would), light beyond an
// opening of the box where the probe's captured distances put it, the probes'
// specular replaces the atlas's specular share instead of adding to it, and rough floors
// above the probes' roughness limit keep the atlas's.
#include <engine/image.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "engine/reflection_probe_test_scene.h"

namespace {

using namespace renderer_test;
using namespace probe_test;

constexpr float kWall = 10.0f;  // W/(m^2 sr): the bright +X wall

// What the probe sees along d: kWall where the ray from kProbe leaves the room through x = 2
// (or, `hall`, the hall through x = kHallEnd), else black; and how far that is.
float room_radiance(glm::vec3 d, bool hall) {
  const SideHit h = side_hit(d, hall ? kHallEnd : kRoomMax.x);
  return h.axis == 0 && d.x > 0.0f ? kWall : 0.0f;
}

// A provider with an irradiance atlas of one texel `e` and one probe of the room above: every
// level holds the room's unfiltered image (the floor's roughness 0.02 reads levels 0 and 1).
// `hall`: the probe stands in the hall instead (its box still the room's) and carries its
// captured distances when `distances`.
ProbeProvider room_probe(float e, float max_roughness, bool hall = false, bool distances = false) {
  const int size = 64, levels = 7;
  std::vector<std::vector<glm::vec3>> texels;
  for (int m = 0; m < levels; ++m)
    texels.push_back(cube_level<glm::vec3>(size >> m, [&](glm::vec3 d) { return glm::vec3(room_radiance(d, hall)); }));
  const std::vector<float> seen_distance =
      cube_level<float>(size, [](glm::vec3 d) { return side_hit(d, kHallEnd).distance; });
  return ProbeProvider(size, texels, distances ? &seen_distance : nullptr,
                       {.atlas_irradiance = e, .max_roughness = max_roughness});
}

// The red radiance of the pixel that sees floor point p (a test failure when p is outside the frame).
float seen(const engine::ImageRgbaF& img, const TestCamera& cam, glm::vec3 p) {
  const glm::ivec2 px = cam.pixel_of(p);
  if (px.x < 0 || px.y < 0 || px.x >= img.width || px.y >= img.height) {
    ADD_FAILURE() << "floor point x = " << p.x << " is outside the frame";
    return -1.0f;
  }
  return red(img, px);
}

// The camera over the floor's line z = 0, looking along +x.
struct Floor : GlossyFloor {
  explicit Floor(float r) : GlossyFloor(r, TestCamera{{-1.5f, 1.5f, 0.0f}, {0.5f, 0.0f, 0.0f}, 1.2f, 97}) {}
};

// On the floor's line z = 0 the view ray from the eye (-1.5, 1.5, 0) reflected at (x, 0, 0)
// runs along (x + 1.5, 1.5, 0): it leaves the room through the bright wall x = 2 before the
// ceiling y = 3 when (2 - x) / (x + 1.5) < 2, i.e. x > -1/3. A cube map read without the box
// (the reflection taken as infinitely far) would put that edge at x = 0.5.
TEST(RendererReflectionProbes, TheBrightWallIsReflectedWhereTheMirrorGeometryPutsIt) {
  engine::GpuContext ctx = headless_context();
  Floor s(0.02f);
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  ProbeProvider probe = room_probe(0.0f, 0.3f);
  r->set_indirect_light(&probe);
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF img = r->read_hdr();
  {  // For a look: build/test_output/reflection_probes/glossy_floor.png (radiance x 2, clamped).
    engine::ImageRgba8 png{img.width, img.height, std::vector<std::uint8_t>(img.pixels.size())};
    for (std::size_t i = 0; i < img.pixels.size(); ++i)
      png.pixels[i] = static_cast<std::uint8_t>(std::clamp(img.pixels[i] * 2.0f, 0.0f, 1.0f) * 255.0f);
    const std::filesystem::path dir = std::filesystem::path(GI_BINARY_DIR) / "test_output" / "reflection_probes";
    std::filesystem::create_directories(dir);
    EXPECT_TRUE(engine::save_png(dir / "glossy_floor.png", png).ok());
  }
  for (float x : {-0.6f, -0.45f}) {
    const glm::vec3 p(x, 0.0f, 0.0f);
    EXPECT_LT(seen(img, s.cam, p), 0.01f * kWall * s.albedo_at(p).specular.x) << "ceiling at x = " << x;
  }
  for (float x : {-0.1f, 0.2f, 0.45f, 1.0f, 1.6f}) {
    const glm::vec3 p(x, 0.0f, 0.0f);
    const float expected = kWall * s.albedo_at(p).specular.x;
    EXPECT_NEAR(seen(img, s.cam, p), expected, 0.03f * expected) << "wall at x = " << x;
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// The hall: the room's +X side is open and the bright wall stands 3 m beyond the probe's box.
// The reflected ray from (x, 0, 0) runs along (x + 1.5, 1.5, 0) and meets the bright wall at
// x = 5 before the ceiling when (5 - x) / (x + 1.5) < 2, i.e. x > 2/3. With its captured
// distances the probe puts the edge there. The box alone reads the probe towards where the ray
// leaves the box, (2, 1.5 (2 - x) / (x + 1.5)) above the probe, and the probe sees the bright
// wall that way only for x > 1: a third of a metre of the reflection goes dark.
TEST(RendererReflectionProbes, LightBeyondTheBoxsOpeningIsReflectedAtItsCapturedDistance) {
  engine::GpuContext ctx = headless_context();
  Floor s(0.02f);
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const auto render = [&](bool distances) {
    ProbeProvider probe = room_probe(0.0f, 0.3f, /*hall=*/true, distances);
    r->set_indirect_light(&probe);
    r->render(s.reg, s.camera);
    engine::ImageRgbaF img = r->read_hdr();
    r->set_indirect_light(nullptr);
    return img;
  };
  const engine::ImageRgbaF with = render(true), box_only = render(false);
  for (float x : {-0.1f, 0.2f, 0.45f}) {
    const glm::vec3 p(x, 0.0f, 0.0f);
    EXPECT_LT(seen(with, s.cam, p), 0.01f * kWall * s.albedo_at(p).specular.x) << "ceiling at x = " << x;
  }
  for (float x : {0.8f, 0.85f, 1.2f, 1.6f}) {
    const glm::vec3 p(x, 0.0f, 0.0f);
    const float expected = kWall * s.albedo_at(p).specular.x;
    EXPECT_NEAR(seen(with, s.cam, p), expected, 0.03f * expected) << "wall at x = " << x;
    if (x < 1.0f) {
      EXPECT_LT(seen(box_only, s.cam, p), 0.01f * expected) << "the box alone at x = " << x;
    }
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// With an atlas of irradiance E, a floor point whose reflection is the dark ceiling shows the
// diffuse lobe's E / pi x albedo alone: the probe's (black) specular replaced the atlas's
// specular share. A rough floor (0.8, above the limit 0.3) keeps the atlas's both lobes.
TEST(RendererReflectionProbes, ProbesReplaceTheAtlasSpecularOnlyBelowTheRoughnessLimit) {
  engine::GpuContext ctx = headless_context();
  const float e = 2.0f;
  const glm::vec3 dark(-0.6f, 0.0f, 0.0f), bright(1.0f, 0.0f, 0.0f);  // both in the frame
  {
    Floor s(0.02f);
    auto r = make_renderer(s.assets, s.cam.size, 0.0f);
    ASSERT_NE(r, nullptr);
    ProbeProvider probe = room_probe(e, 0.3f);
    r->set_indirect_light(&probe);
    r->render(s.reg, s.camera);
    const engine::ImageRgbaF img = r->read_hdr();
    const float diffuse = e / kPi * s.albedo_at(dark).diffuse.x;
    EXPECT_NEAR(seen(img, s.cam, dark), diffuse, 0.02f * diffuse);
    const float lit = e / kPi * s.albedo_at(bright).diffuse.x + kWall * s.albedo_at(bright).specular.x;
    EXPECT_NEAR(seen(img, s.cam, bright), lit, 0.03f * lit);
  }
  {
    Floor s(0.8f);
    auto r = make_renderer(s.assets, s.cam.size, 0.0f);
    ASSERT_NE(r, nullptr);
    ProbeProvider probe = room_probe(e, 0.3f);
    r->set_indirect_light(&probe);
    r->render(s.reg, s.camera);
    const engine::ImageRgbaF img = r->read_hdr();
    for (const glm::vec3& p : {dark, bright}) {
      const float atlas = e / kPi * s.albedo_at(p).sum().x;
      EXPECT_NEAR(seen(img, s.cam, p), atlas, 0.02f * atlas) << "rough floor at x = " << p.x;
    }
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace
