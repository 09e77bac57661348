// Reflection probes in the forward pass (engine/indirect_light.h, reflection_probe_*;
// engine/shaders/reflection_probes.glsl), on llvmpipe: a glossy floor in a 4 x 3 x 4 m room
// whose +X wall is bright shows the wall's reflection exactly where the mirror geometry of
// the room's box puts it (not where an infinitely distant cube map would), light beyond an
// opening of the box where the probe's captured distances put it, the probes'
// specular replaces the atlas's specular share instead of adding to it, and rough floors
// above the probes' roughness limit keep the atlas's.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <engine/gltf_brdf.h>
#include <engine/image.h>
#include <engine/indirect_light.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr float kWall = 10.0f;  // W/(m^2 sr): the bright +X wall
const glm::vec3 kRoomMin(-2.0f, 0.0f, -2.0f);
const glm::vec3 kRoomMax(2.0f, 3.0f, 2.0f);
const glm::vec3 kProbe(0.0f, 1.5f, 0.0f);

// The room seen from the probe: kWall where the ray from kProbe along d leaves the box through
// x = 2, else black.
float room_radiance(glm::vec3 d) {
  float t = 1e30f;
  int axis = 0;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) continue;
    const float ta = ((d[a] > 0.0f ? kRoomMax[a] : kRoomMin[a]) - kProbe[a]) / d[a];
    if (ta < t) t = ta, axis = a;
  }
  return axis == 0 && d.x > 0.0f ? kWall : 0.0f;
}

// GL's cube-map face directions (OpenGL 4.6 table 8.19) for face coordinates u, v in [-1, 1].
glm::vec3 face_direction(int face, float u, float v) {
  switch (face) {
    case 0:
      return {1.0f, -v, -u};
    case 1:
      return {-1.0f, -v, u};
    case 2:
      return {u, 1.0f, v};
    case 3:
      return {u, -1.0f, -v};
    case 4:
      return {u, -v, 1.0f};
    default:
      return {-u, -v, -1.0f};
  }
}

// A hall that runs on beyond the probe's box: its bright wall at x = kHallEnd, the box (and
// the room's other walls) as above. What the probe at kProbe sees: radiance and distance.
constexpr float kHallEnd = 5.0f;
struct Seen {
  float radiance = 0.0f, distance = 0.0f;
};
Seen hall_seen(glm::vec3 d) {
  const glm::vec3 hi(kHallEnd, kRoomMax.y, kRoomMax.z);
  float t = 1e30f;
  int axis = 0;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) continue;
    const float ta = ((d[a] > 0.0f ? hi[a] : kRoomMin[a]) - kProbe[a]) / d[a];
    if (ta < t) t = ta, axis = a;
  }
  return {axis == 0 && d.x > 0.0f ? kWall : 0.0f, t};
}

// A provider with an irradiance atlas of one texel `e` and one probe of the room above: every
// level holds the room's unfiltered image (the floor's roughness 0.02 reads levels 0 and 1).
// `hall`: the probe stands in the hall instead (its box still the room's) and carries its
// captured distances when `distances`.
class RoomProbe : public engine::IndirectLightProvider {
 public:
  RoomProbe(float e, float max_roughness, bool hall = false, bool distances = false) {
    glCreateTextures(GL_TEXTURE_2D, 1, &atlas_);
    glTextureStorage2D(atlas_, 1, GL_RGBA32F, 1, 1);
    const float texel[4] = {e, e, e, 1.0f};
    glTextureSubImage2D(atlas_, 0, 0, 0, 1, 1, GL_RGBA, GL_FLOAT, texel);
    const int size = 64, levels = 7;
    glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &cubes_);
    glTextureStorage3D(cubes_, levels, GL_RGBA16F, size, size, 6);
    for (int m = 0; m < levels; ++m) {
      const int s = size >> m;
      std::vector<float> texels;
      for (int f = 0; f < 6; ++f)
        for (int y = 0; y < s; ++y)
          for (int x = 0; x < s; ++x) {
            const float u = (2.0f * static_cast<float>(x) + 1.0f) / static_cast<float>(s) - 1.0f;
            const float v = (2.0f * static_cast<float>(y) + 1.0f) / static_cast<float>(s) - 1.0f;
            const glm::vec3 d = glm::normalize(face_direction(f, u, v));
            const float l = hall ? hall_seen(d).radiance : room_radiance(d);
            texels.insert(texels.end(), {l, l, l});
          }
      glTextureSubImage3D(cubes_, m, 0, 0, 0, s, s, 6, GL_RGB, GL_FLOAT, texels.data());
    }
    glTextureParameteri(cubes_, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(cubes_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    if (distances) {
      glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &distances_);
      glTextureStorage3D(distances_, 1, GL_R32F, size, size, 6);
      std::vector<float> texels;
      for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
          for (int x = 0; x < size; ++x) {
            const float u = (2.0f * static_cast<float>(x) + 1.0f) / static_cast<float>(size) - 1.0f;
            const float v = (2.0f * static_cast<float>(y) + 1.0f) / static_cast<float>(size) - 1.0f;
            texels.push_back(hall_seen(glm::normalize(face_direction(f, u, v))).distance);
          }
      glTextureSubImage3D(distances_, 0, 0, 0, 0, size, size, 6, GL_RED, GL_FLOAT, texels.data());
      glTextureParameteri(distances_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(distances_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      frame_.reflection_probe_distances = {distances_};
    }
    const engine::ReflectionProbeBox box{glm::vec4(kProbe, 0.0f), glm::vec4(kRoomMin, 0.0f), glm::vec4(kRoomMax, 0.0f)};
    glCreateBuffers(1, &boxes_);
    glNamedBufferStorage(boxes_, sizeof box, &box, 0);
    frame_.irradiance_atlas_texture = {atlas_};
    frame_.reflection_probe_cubes = {cubes_};
    frame_.reflection_probe_buffer = engine::SsboHandle<engine::ReflectionProbeBox>{boxes_};
    frame_.reflection_probe_count = 1;
    frame_.reflection_probe_levels = levels;
    frame_.reflection_probe_max_roughness = max_roughness;
  }
  ~RoomProbe() override {
    glDeleteTextures(1, &atlas_);
    glDeleteTextures(1, &cubes_);
    if (distances_ != 0) glDeleteTextures(1, &distances_);
    glDeleteBuffers(1, &boxes_);
  }
  RoomProbe(const RoomProbe&) = delete;
  RoomProbe& operator=(const RoomProbe&) = delete;
  const engine::IndirectLightFrame& frame() override { return frame_; }
  const char* label() const override { return "test room probe"; }
  engine::IndirectLightFrame frame_;

 private:
  GLuint atlas_ = 0, cubes_ = 0, distances_ = 0, boxes_ = 0;
};

// The red radiance of the pixel that sees floor point p (a test failure when p is outside the frame).
float seen(const engine::ImageRgbaF& img, const TestCamera& cam, glm::vec3 p) {
  const glm::ivec2 px = cam.pixel_of(p);
  if (px.x < 0 || px.y < 0 || px.x >= img.width || px.y >= img.height) {
    ADD_FAILURE() << "floor point x = " << p.x << " is outside the frame";
    return -1.0f;
  }
  return red(img, px);
}

struct GlossyFloor {
  engine::SceneAsset assets;
  engine::Registry reg;
  TestCamera cam{{-1.5f, 1.5f, 0.0f}, {0.5f, 0.0f, 0.0f}, 1.2f, 97};
  engine::Entity camera;
  float roughness;

  explicit GlossyFloor(float r) : roughness(r) {
    assets.materials.push_back(diffuse_material(0.5f, r));
    assets.meshes.push_back(plane_mesh(2.0f, 0));
    add_mesh(reg, 0, glm::mat4(1.0f), /*is_static=*/true);
    camera = cam.add_to(reg);
  }
  // The floor's directional albedo per lobe at floor point p seen from the camera.
  engine::GltfBrdfValue albedo_at(glm::vec3 p) const {
    const float cos_v = glm::normalize(cam.eye - p).y;
    return engine::gltf_directional_albedo(engine::gltf_brdf(glm::vec3(0.5f), 0.0f, roughness), cos_v);
  }
};

// On the floor's line z = 0 the view ray from the eye (-1.5, 1.5, 0) reflected at (x, 0, 0)
// runs along (x + 1.5, 1.5, 0): it leaves the room through the bright wall x = 2 before the
// ceiling y = 3 when (2 - x) / (x + 1.5) < 2, i.e. x > -1/3. A cube map read without the box
// (the reflection taken as infinitely far) would put that edge at x = 0.5.
TEST(RendererReflectionProbes, TheBrightWallIsReflectedWhereTheMirrorGeometryPutsIt) {
  engine::GpuContext ctx = headless_context();
  GlossyFloor s(0.02f);
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  RoomProbe probe(0.0f, 0.3f);
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
  GlossyFloor s(0.02f);
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const auto render = [&](bool distances) {
    RoomProbe probe(0.0f, 0.3f, /*hall=*/true, distances);
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
    GlossyFloor s(0.02f);
    auto r = make_renderer(s.assets, s.cam.size, 0.0f);
    ASSERT_NE(r, nullptr);
    RoomProbe probe(e, 0.3f);
    r->set_indirect_light(&probe);
    r->render(s.reg, s.camera);
    const engine::ImageRgbaF img = r->read_hdr();
    const float diffuse = e / kPi * s.albedo_at(dark).diffuse.x;
    EXPECT_NEAR(seen(img, s.cam, dark), diffuse, 0.02f * diffuse);
    const float lit = e / kPi * s.albedo_at(bright).diffuse.x + kWall * s.albedo_at(bright).specular.x;
    EXPECT_NEAR(seen(img, s.cam, bright), lit, 0.03f * lit);
  }
  {
    GlossyFloor s(0.8f);
    auto r = make_renderer(s.assets, s.cam.size, 0.0f);
    ASSERT_NE(r, nullptr);
    RoomProbe probe(e, 0.3f);
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
