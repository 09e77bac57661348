// The forward shader's probe lookup at the view (engine/shaders/reflection_probes.glsl,
// probe_lobe) against its CPU twin (gi's probe_lobe_radiance, reflection_probes/probe_cube.h),
// on llvmpipe through EGL (never skipped): a glossy floor seen at grazing angles in a room
// whose +X side opens into a hall, the probe a real prefiltered cube with captured distances.
#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/gltf_brdf.h>
#include <engine/gpu/gl_objects.h>
#include <engine/image.h>
#include <engine/indirect_light.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "../../../tests/engine/renderer_test_scene.h"
#include "reflection_probes/probe_cube.h"

namespace {

using namespace renderer_test;

const glm::vec3 kRoomMin(-2.0f, 0.0f, -2.0f), kRoomMax(2.0f, 3.0f, 2.0f), kProbe(0.0f, 1.5f, 0.0f);
constexpr float kHallEnd = 5.0f;  // the hall's far wall, 3 m beyond the probe's box

// What the probe sees along d: the hall [-2, 5] x [0, 3] x [-2, 2]; the far wall bright with a
// dark 1 m wide opening in its middle, the other sides of different greys.
struct Seen {
  float radiance = 0.0f, distance = 0.0f;
};
Seen hall_seen(const glm::vec3& d) {
  const glm::vec3 hi(kHallEnd, kRoomMax.y, kRoomMax.z);
  float t = 1e30f;
  int axis = 0;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) continue;
    const float ta = ((d[a] > 0.0f ? hi[a] : kRoomMin[a]) - kProbe[a]) / d[a];
    if (ta < t) t = ta, axis = a;
  }
  const glm::vec3 q = kProbe + t * d;
  float l = 1.0f;  // side walls
  if (axis == 0) l = d.x > 0.0f ? (std::abs(q.z) < 0.5f ? 0.2f : 10.0f) : 2.0f;
  if (axis == 1) l = d.y > 0.0f ? 0.5f : 0.3f;
  return {l, t};
}

gi::ProbeCube hall_cube(int size) {
  gi::ProbeCube cube = gi::make_probe_cube(size, gi::full_mip_count(size));
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const Seen s = hall_seen(gi::cube_texel_direction(f, x, y, size));
        cube.levels[0][gi::cube_texel_index(f, x, y, size)] = glm::vec3(s.radiance);
        cube.distance[gi::cube_texel_index(f, x, y, size)] = s.distance;
      }
  gi::prefilter_ggx(cube, 64);
  return cube;
}

// The probe as the runtime hands it to the renderer (reflection_probes_method.cpp's upload),
// with an atlas of irradiance 0: the floor shows the probe's specular alone.
class HallProbe : public engine::IndirectLightProvider {
 public:
  HallProbe(const gi::ProbeCube& cube, int lobe_samples) {
    const int levels = static_cast<int>(cube.levels.size());
    atlas_ = engine::GlTexture::create_2d(GL_RGBA32F, 1, 1);
    const float zero[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    glTextureSubImage2D(atlas_.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_FLOAT, zero);
    cubes_ = engine::GlTexture::create_cube_array(GL_RGBA16F, cube.size, 1, levels);
    for (int m = 0; m < levels; ++m) {
      const int s = gi::cube_level_size(cube.size, m);
      glTextureSubImage3D(cubes_.id(), m, 0, 0, 0, s, s, 6, GL_RGB, GL_FLOAT,
                          cube.levels[static_cast<std::size_t>(m)].data());
    }
    glTextureParameteri(cubes_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(cubes_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    distances_ = engine::GlTexture::create_cube_array(GL_R32F, cube.size, 1, 1);
    glTextureSubImage3D(distances_.id(), 0, 0, 0, 0, cube.size, cube.size, 6, GL_RED, GL_FLOAT, cube.distance.data());
    glTextureParameteri(distances_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(distances_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    const engine::ReflectionProbeBox box{glm::vec4(kProbe, 0.0f), glm::vec4(kRoomMin, 0.0f), glm::vec4(kRoomMax, 0.0f)};
    boxes_ = engine::GlBuffer::create(sizeof box, &box);
    frame_.irradiance_atlas_texture = {atlas_.id()};
    frame_.reflection_probe_cubes = {cubes_.id()};
    frame_.reflection_probe_distances = {distances_.id()};
    frame_.reflection_probe_buffer = engine::SsboHandle<engine::ReflectionProbeBox>{boxes_.id()};
    frame_.reflection_probe_count = 1;
    frame_.reflection_probe_levels = levels;
    frame_.reflection_probe_max_roughness = 0.3f;
    frame_.reflection_probe_lobe_samples = lobe_samples;
  }
  const engine::IndirectLightFrame& frame() override { return frame_; }
  const char* label() const override { return "test hall probe"; }

 private:
  engine::IndirectLightFrame frame_;
  engine::GlTexture atlas_, cubes_, distances_;
  engine::GlBuffer boxes_;
};

// Every floor pixel well inside the room (0.1 m from its sides), the camera low over the floor
// (cos(theta_v) 0.1-0.45): the shader's lobe lookup at 8 samples is its CPU twin's within 3%
// (+ 0.002 absolute; the cube is stored as half floats on the GPU, the GPU filters seamlessly
// across face edges where the twin clamps) at 95% of the pixels and within 1% on the mean, and
// differs from the split sum's single read by more than 10% at a fifth of them or more (the
// lookup is the one the frame asked for).
TEST(ReflectionProbesLobe, TheShadersLobeLookupIsItsCpuTwinsAtGrazingViews) {
  engine::GpuContext ctx = headless_context();
  const float roughness = 0.2f;
  const int samples = 8;
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(0.5f, roughness));
  assets.meshes.push_back(plane_mesh(2.0f, 0));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f), /*is_static=*/true);
  const TestCamera cam{{-1.9f, 0.6f, 0.0f}, {1.5f, 0.0f, 0.0f}, 1.0f, 81};
  const engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const gi::ProbeCube cube = hall_cube(32);
  const auto render = [&](int lobe_samples) {
    HallProbe probe(cube, lobe_samples);
    r->set_indirect_light(&probe);
    r->render(reg, camera);
    engine::ImageRgbaF img = r->read_hdr();
    r->set_indirect_light(nullptr);
    return img;
  };
  const engine::ImageRgbaF lobe = render(samples), split = render(0);
  const engine::GltfBrdf brdf = engine::gltf_brdf(glm::vec3(0.5f), 0.0f, roughness);
  int pixels = 0, close = 0, differs = 0;
  double sum_gpu = 0.0, sum_cpu = 0.0;
  for (int py = 0; py < cam.size; ++py)
    for (int px = 0; px < cam.size; ++px) {
      const glm::vec3 p = cam.plane_point(px, py);
      if (!(p.y == p.y) || std::abs(p.x) > 1.9f || std::abs(p.z) > 1.9f || glm::dot(p - cam.eye, p - cam.eye) > 100.0f)
        continue;
      if (glm::dot(cam.plane_point(px, py) - cam.eye, cam.target - cam.eye) <= 0.0f) continue;
      const glm::vec3 v = glm::normalize(cam.eye - p), up(0.0f, 1.0f, 0.0f);
      const float albedo = engine::gltf_directional_albedo(brdf, v.y).specular.x;
      const float cpu =
          gi::probe_lobe_radiance(cube, brdf, p, up, v, samples, kProbe, kRoomMin, kRoomMax, false).x * albedo;
      const float gpu = red(lobe, px, py);
      ++pixels;
      sum_gpu += static_cast<double>(gpu);
      sum_cpu += static_cast<double>(cpu);
      if (std::abs(gpu - cpu) <= 0.03f * cpu + 0.002f) ++close;
      if (std::abs(red(split, px, py) - gpu) > 0.1f * gpu) ++differs;
    }
  std::printf("%d floor pixels: %d within 3%% of the twin, mean GPU %.4f CPU %.4f, %d differ from the split sum\n",
              pixels, close, sum_gpu / pixels, sum_cpu / pixels, differs);
  ASSERT_GT(pixels, 1000);
  EXPECT_GE(close, pixels * 95 / 100);
  EXPECT_NEAR(sum_gpu, sum_cpu, 0.01 * sum_cpu);
  EXPECT_GE(differs, pixels / 5);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace
