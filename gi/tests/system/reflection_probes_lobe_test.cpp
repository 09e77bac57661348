// The forward shader's probe lookup at the view (engine/shaders/reflection_probes.glsl,
// probe_lobe) against its CPU twin (gi's probe_lobe_radiance, reflection_probes/probe_cube.h),
// on llvmpipe through EGL (never skipped): a glossy floor seen at grazing angles in a room
// whose +X side opens into a hall, the probe a real prefiltered cube with captured distances.
#include <gtest/gtest.h>
#include <engine/gltf_brdf.h>
#include <engine/image.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "../../../tests/engine/reflection_probe_test_scene.h"
#include "reflection_probes/probe_cube.h"
#include "reflection_probes/reflection_probes.h"

namespace {

using namespace renderer_test;
using namespace probe_test;

const glm::vec3 kUp(0.0f, 1.0f, 0.0f);

// What the probe sees along d: the hall [-2, 5] x [0, 3] x [-2, 2]; the far wall bright with a
// dark 1 m wide opening in its middle, the other sides of different greys.
float hall_radiance(const SideHit& h, const glm::vec3& d) {
  if (h.axis == 0) return d.x > 0.0f ? (std::abs(h.point.z) < 0.5f ? 0.2f : 10.0f) : 2.0f;
  if (h.axis == 1) return d.y > 0.0f ? 0.5f : 0.3f;
  return 1.0f;  // side walls
}

gi::ProbeCube hall_cube(int size) {
  gi::ProbeCube cube = gi::make_probe_cube(size, gi::full_mip_count(size));
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 d = gi::cube_texel_direction(f, x, y, size);
        cube.levels[0][gi::cube_texel_index(f, x, y, size)] = glm::vec3(hall_radiance(side_hit(d, kHallEnd), d));
      }
  // The distances as the bake stores them, kProbeDistanceScale x level 0's size.
  const int ds = gi::kProbeDistanceScale * size;
  cube.distance_size = ds;
  cube.distance.resize(static_cast<std::size_t>(6 * ds * ds));
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < ds; ++y)
      for (int x = 0; x < ds; ++x)
        cube.distance[gi::cube_texel_index(f, x, y, ds)] =
            side_hit(gi::cube_texel_direction(f, x, y, ds), kHallEnd).distance;
  gi::prefilter_ggx(cube, 64);
  return cube;
}

// Calls f(px, py, p, v, albedo) at every floor pixel of `cam` well inside the room (0.1 m from
// its sides), in front of the camera and within 10 m of it: the floor point p, the view v and the
// specular lobe's directional albedo there (red channel) for `brdf`.
template <typename F>
void for_each_floor_pixel(const TestCamera& cam, const engine::GltfBrdf& brdf, F&& f) {
  for (int py = 0; py < cam.size; ++py)
    for (int px = 0; px < cam.size; ++px) {
      const glm::vec3 p = cam.plane_point(px, py);
      if (!(p.y == p.y) || std::abs(p.x) > 1.9f || std::abs(p.z) > 1.9f || glm::dot(p - cam.eye, p - cam.eye) > 100.0f)
        continue;
      if (glm::dot(p - cam.eye, cam.target - cam.eye) <= 0.0f) continue;
      const glm::vec3 v = glm::normalize(cam.eye - p);
      f(px, py, p, v, engine::gltf_directional_albedo(brdf, v.y).specular.x);
    }
}

// The shader against a CPU twin whose branch (`with` / `without` it) decides some pixels: all
// pixels, those within 3% (+ 0.002) of the twin with it, those where the two twins differ by
// more than 10% (decided), and of those the ones within 5% (+ 0.002) of it and nearer it.
struct BranchCounts {
  int pixels = 0, close = 0, decided = 0, decided_close = 0, decided_nearer = 0;
  void add(float gpu, float with, float without) {
    ++pixels;
    if (std::abs(gpu - with) <= 0.03f * with + 0.002f) ++close;
    if (std::abs(with - without) <= 0.1f * std::max(with, without)) return;
    ++decided;
    if (std::abs(gpu - with) <= 0.05f * with + 0.002f) ++decided_close;
    if (std::abs(gpu - with) < std::abs(gpu - without)) ++decided_nearer;
  }
  // The branch decides a tenth of the floor or more; there the shader follows it at 90% of the
  // pixels; everywhere it is the twin within 3% at 95%.
  void expect(const char* branch) const {
    std::printf("%d floor pixels (%d within 3%% of the twin); %s decides %d: %d within 5%%, %d nearer\n", pixels, close,
                branch, decided, decided_close, decided_nearer);
    ASSERT_GT(pixels, 1000);
    EXPECT_GE(decided, pixels / 10);
    EXPECT_GE(decided_close, decided * 9 / 10);
    EXPECT_GE(decided_nearer, decided * 9 / 10);
    EXPECT_GE(close, pixels * 95 / 100);
  }
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
  GlossyFloor s(roughness, TestCamera{{-1.9f, 0.6f, 0.0f}, {1.5f, 0.0f, 0.0f}, 1.0f, 81});
  const TestCamera& cam = s.cam;
  auto r = make_renderer(s.assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const gi::ProbeCube cube = hall_cube(32);
  const auto render = [&](int lobe_samples) {
    ProbeProvider probe(cube.size, cube.levels, &cube.distance, {.lobe_samples = lobe_samples});
    r->set_indirect_light(&probe);
    r->render(s.reg, s.camera);
    engine::ImageRgbaF img = r->read_hdr();
    r->set_indirect_light(nullptr);
    return img;
  };
  const engine::ImageRgbaF lobe = render(samples), split = render(0);
  const engine::GltfBrdf brdf = s.brdf();
  int pixels = 0, close = 0, differs = 0;
  double sum_gpu = 0.0, sum_cpu = 0.0;
  for_each_floor_pixel(cam, brdf, [&](int px, int py, const glm::vec3& p, const glm::vec3& v, float albedo) {
    const float cpu =
        gi::probe_lobe_radiance(cube, brdf, p, kUp, v, samples, kProbe, kRoomMin, kRoomMax, false).x * albedo;
    const float gpu = red(lobe, px, py);
    ++pixels;
    sum_gpu += static_cast<double>(gpu);
    sum_cpu += static_cast<double>(cpu);
    if (std::abs(gpu - cpu) <= 0.03f * cpu + 0.002f) ++close;
    if (std::abs(red(split, px, py) - gpu) > 0.1f * gpu) ++differs;
  });
  std::printf("%d floor pixels: %d within 3%% of the twin, mean GPU %.4f CPU %.4f, %d differ from the split sum\n",
              pixels, close, sum_gpu / pixels, sum_cpu / pixels, differs);
  ASSERT_GT(pixels, 1000);
  EXPECT_GE(close, pixels * 95 / 100);
  EXPECT_NEAR(sum_gpu, sum_cpu, 0.01 * sum_cpu);
  EXPECT_GE(differs, pixels / 5);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// The runtime's count, which grows at grazing views (4 samples along the normal, up to 32,
// gi's probe_lobe_sample_count, the shader's probe_lobe_count), on the same floor: the shader is
// its CPU twin at each pixel's own count within 3% (+ 0.002) at 95% of the pixels and within 1% on
// the mean; the floor's pixels take 16 and 32 samples, each at a tenth of them or more; and the
// twin at 4 samples differs from the shader by more than 5% at a tenth of them or more (the
// count is the one the view asks for, not the base count).
TEST(ReflectionProbesLobe, TheShadersGrazingSampleCountIsItsCpuTwins) {
  engine::GpuContext ctx = headless_context();
  const float roughness = 0.2f;
  GlossyFloor s(roughness, TestCamera{{-1.9f, 0.6f, 0.0f}, {1.5f, 0.0f, 0.0f}, 1.0f, 81});
  const TestCamera& cam = s.cam;
  auto r = make_renderer(s.assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const gi::ProbeCube cube = hall_cube(32);
  ProbeProvider probe(cube.size, cube.levels, &cube.distance,
                      {.lobe_samples = gi::kProbeLobeSamples, .lobe_samples_max = gi::kProbeGrazingLobeSamples});
  r->set_indirect_light(&probe);
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF img = r->read_hdr();
  r->set_indirect_light(nullptr);
  const engine::GltfBrdf brdf = s.brdf();
  int pixels = 0, close = 0, base_differs = 0, at16 = 0, at32 = 0;
  double sum_gpu = 0.0, sum_cpu = 0.0;
  for_each_floor_pixel(cam, brdf, [&](int px, int py, const glm::vec3& p, const glm::vec3& v, float albedo) {
    const int count = gi::probe_lobe_sample_count(gi::kProbeLobeSamples, gi::kProbeGrazingLobeSamples, v.y);
    const auto twin = [&](int samples) {
      return gi::probe_lobe_radiance(cube, brdf, p, kUp, v, samples, kProbe, kRoomMin, kRoomMax, false).x * albedo;
    };
    const float cpu = twin(count), gpu = red(img, px, py);
    ++pixels;
    at16 += count == 16 ? 1 : 0;
    at32 += count == 32 ? 1 : 0;
    sum_gpu += static_cast<double>(gpu);
    sum_cpu += static_cast<double>(cpu);
    if (std::abs(gpu - cpu) <= 0.03f * cpu + 0.002f) ++close;
    if (std::abs(twin(gi::kProbeLobeSamples) - gpu) > 0.05f * gpu) ++base_differs;
  });
  std::printf(
      "%d floor pixels (%d at 16 samples, %d at 32): %d within 3%% of the twin, mean GPU %.4f CPU %.4f, "
      "%d differ from 4 samples\n",
      pixels, at16, at32, close, sum_gpu / pixels, sum_cpu / pixels, base_differs);
  ASSERT_GT(pixels, 1000);
  EXPECT_GE(at16, pixels / 10);
  EXPECT_GE(at32, pixels / 10);
  EXPECT_GE(close, pixels * 95 / 100);
  EXPECT_NEAR(sum_gpu, sum_cpu, 0.01 * sum_cpu);
  EXPECT_GE(base_differs, pixels / 10);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// A slatted +X side: the room's +X wall at x = 2 m is cut into vertical slats one level-0
// texel wide (alternate texel columns of the +X face, 0.06-0.12 m at 2 m), bright jambs
// between dark openings onto the hall's far wall at x = 5 m. Every exit through that side then
// lies within a texel of an opening's rim, where the bilinear mean distance mixes the jamb's
// 2 m with the hall's 5 m: the box-first test at the rim (kProbeRimNearest, the shader's
// PROBE_RIM_NEAREST branch, probe_rim_is_side) decides the lookup there.
gi::ProbeCube slatted_cube(int size) {
  gi::ProbeCube cube = gi::make_probe_cube(size, gi::full_mip_count(size));
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 d = gi::cube_texel_direction(f, x, y, size);
        const SideHit room = side_hit(d, kRoomMax.x);
        const bool jamb = f == 0 && room.axis == 0 && x % 2 == 0;
        const SideHit h = jamb ? room : side_hit(d, kHallEnd);
        // The hall's far wall: a gradient along z, so a lookup sent elsewhere along it reads differently.
        const float far_wall = 0.3f + 0.4f * (h.point.z + 2.0f);
        const float l = jamb ? 8.0f : h.axis == 0 && d.x > 0.0f ? far_wall : hall_radiance(h, d);
        cube.levels[0][gi::cube_texel_index(f, x, y, size)] = glm::vec3(l);
        cube.distance[gi::cube_texel_index(f, x, y, size)] = h.distance;
      }
  gi::prefilter_ggx(cube, 64);
  return cube;
}

// The shader's rim branch against its CPU twin: a floor of roughness 0.05 seen low towards the
// slatted side (4 lobe samples, the runtime's count). The twin with the rim's test and without
// it differ by more than 10% at a tenth of the floor's pixels or more (the branch decides
// there); at those pixels the shader is the twin with the test within 5% (+ 0.002) at 90% of
// them and nearer it than the twin without at 90%, and over the whole floor within 3% at 95%.
// A shader whose rim branch never fired, or always fired, fails the second pair.
TEST(ReflectionProbesLobe, TheShadersRimTestIsItsCpuTwinsAtASlattedSide) {
  engine::GpuContext ctx = headless_context();
  const float roughness = 0.05f;
  const int samples = 4;
  GlossyFloor s(roughness, TestCamera{{-1.9f, 0.6f, 0.0f}, {1.5f, 0.0f, 0.0f}, 1.0f, 81});
  const TestCamera& cam = s.cam;
  auto r = make_renderer(s.assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const gi::ProbeCube cube = slatted_cube(32);
  ProbeProvider probe(cube.size, cube.levels, &cube.distance, {.lobe_samples = samples});
  r->set_indirect_light(&probe);
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF img = r->read_hdr();
  r->set_indirect_light(nullptr);
  const engine::GltfBrdf brdf = s.brdf();
  BranchCounts counts;
  for_each_floor_pixel(cam, brdf, [&](int px, int py, const glm::vec3& p, const glm::vec3& v, float albedo) {
    const auto twin = [&](bool rim) {
      return gi::probe_lobe_radiance(cube, brdf, p, kUp, v, samples, kProbe, kRoomMin, kRoomMax, false, nullptr,
                                     gi::kProbeBoxSideTolerance, rim)
                 .x *
             albedo;
    };
    counts.add(red(img, px, py), twin(true), twin(false));
  });
  counts.expect("the rim's test");
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// The hall seen from `centre` (its sides' radiance times `gain`); with `blocker`, a dark object
// 0.8 m from the centre fills the directions down towards the floor's +x half (d.x > 0.35, d.y <
// -0.45), so the probe does not see the floor at x > 0.8 m, |z| < 1.3 m or so.
gi::ProbeCube hall_cube_from(glm::vec3 centre, float gain, bool blocker) {
  const int size = 32;
  gi::ProbeCube cube = gi::make_probe_cube(size, gi::full_mip_count(size));
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 d = gi::cube_texel_direction(f, x, y, size);
        const SideHit h = side_hit(d, kHallEnd, centre);
        const bool blocked = blocker && d.x > 0.35f && d.y < -0.45f;
        cube.levels[0][gi::cube_texel_index(f, x, y, size)] = glm::vec3(blocked ? 0.05f : gain * hall_radiance(h, d));
        cube.distance[gi::cube_texel_index(f, x, y, size)] = blocked ? 0.8f : h.distance;
      }
  gi::prefilter_ggx(cube, 64);
  return cube;
}

// The blend weighted by whether each probe saw the point (the shader's probe_weight x
// probe_visibility) against its CPU twin (gi's blended_probe_lobe): two probes share the room's
// box, A at its centre with a blocker hiding the floor's +x part, B 0.8 m up over that part,
// seeing everything, its light a third brighter. The twin with the visibility weight and without
// it differ by more than 10% at a tenth of the floor's pixels or more (there B alone is read);
// there the shader is the twin with it within 5% (+ 0.002) at 90% and nearer it than the other at
// 90%; over the whole floor within 3% at 95%.
TEST(ReflectionProbesLobe, TheShadersVisibilityWeightedBlendIsItsCpuTwins) {
  engine::GpuContext ctx = headless_context();
  const int samples = 4;
  GlossyFloor s(0.1f, TestCamera{{-1.9f, 0.6f, 0.0f}, {1.5f, 0.0f, 0.0f}, 1.0f, 81});
  const TestCamera& cam = s.cam;
  auto r = make_renderer(s.assets, cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  const glm::vec3 second(1.2f, 0.8f, 0.0f);
  const std::vector<gi::ProbeCube> cubes = {hall_cube_from(kProbe, 1.0f, true), hall_cube_from(second, 1.3f, false)};
  const std::vector<gi::ProbeVolume> probes = {{kProbe, kRoomMin, kRoomMax}, {second, kRoomMin, kRoomMax}};
  ProbeProvider provider(
      32, {{kProbe, &cubes[0].levels, &cubes[0].distance}, {second, &cubes[1].levels, &cubes[1].distance}},
      {.lobe_samples = samples});
  r->set_indirect_light(&provider);
  r->render(s.reg, s.camera);
  const engine::ImageRgbaF img = r->read_hdr();
  r->set_indirect_light(nullptr);
  const engine::GltfBrdf brdf = s.brdf();
  BranchCounts counts;
  for_each_floor_pixel(cam, brdf, [&](int px, int py, const glm::vec3& p, const glm::vec3& v, float albedo) {
    const auto twin = [&](bool visibility) {
      glm::vec3 out(0.0f);
      EXPECT_TRUE(gi::blended_probe_lobe(probes, cubes, brdf, p, kUp, v, samples, out, visibility));
      return out.x * albedo;
    };
    counts.add(red(img, px, py), twin(true), twin(false));
  });
  counts.expect("the visibility weight");
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace
