// RenderSettings::area_shadow_res: the area light's soft-shadow visibility computed at half
// resolution and upsampled on each pixel's own surface gives the image the full-resolution
// lookups give, penumbra included, and never lends one surface's shadow to another.
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr int kSize = 192;

// A floor, a plate 1 m up over x < 0 (a wide penumbra on the floor), a box standing on the
// floor (silhouettes of lit tops against shadowed floor, contact shadows) and a second box
// floating in front of the back wall; a 0.6 m area light 2 m up. Seen obliquely.
engine::ImageRgbaF frame(engine::AreaShadowRes res, bool casters = true) {
  engine::SceneAsset assets;
  assets.materials.push_back(diffuse_material(0.5f));
  assets.meshes.push_back(plane_mesh(3.0f, 0));
  engine::Mesh plate;
  plate.name = "plate";
  plate.primitives.emplace_back();
  plate.primitives[0].material = 0;
  add_quad(plate.primitives[0], glm::vec3(-1.5f, 1.0f, -0.5f), glm::vec3(0, 0, 1.0f), glm::vec3(1.5f, 0, 0));
  assets.meshes.push_back(plate);
  assets.meshes.push_back(box_mesh(glm::vec3(0.2f), 0));
  engine::Registry reg;
  add_mesh(reg, 0, glm::mat4(1.0f));
  if (casters) {
    add_mesh(reg, 1, glm::mat4(1.0f));
    add_mesh(reg, 2, glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, 0.2f, 0.6f)));
    add_mesh(reg, 2, glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, 0.6f, -0.4f)), false);
  }
  add_light(reg, engine::Light{.type = engine::LightType::Area, .intensity = 20.0f, .area_size_m = {0.6f, 0.6f}},
            {0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f});
  const TestCamera cam{{0.4f, 1.6f, 2.6f}, {0.0f, 0.2f, 0.0f}, 0.9f, kSize};
  const engine::Entity camera = cam.add_to(reg);
  auto r = make_renderer(assets, kSize, 0.0f);
  if (!r) return {};
  r->settings().shadow_map_size = 1024;
  r->settings().area_shadow_res = res;
  r->render(reg, camera);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  return r->read_hdr();
}

}  // namespace

// Half against full resolution on the same frame. The half-resolution value of a pixel is a
// convex combination of the visibility at up to 4 points of its own surface within 1.5
// pixels, so it must lie within the range the full-resolution frame takes over the pixel's
// 5 x 5 neighbourhood (allowing 2% of the peak for the PCSS estimate's own variation between
// nearby points: 12 taps, i.e. steps of 1/12 smoothed by bilinear compares). In 95% of the
// pixels the difference must stay below 1% of the peak (smooth regions interpolate exactly);
// the penumbra under the plate must be there, as wide, in both.
TEST(RendererAreaShadowRes, HalfResolutionMatchesFullWithinTheNeighbourhood) {
  engine::GpuContext ctx = headless_context();
  const engine::ImageRgbaF full = frame(engine::AreaShadowRes::Full);
  const engine::ImageRgbaF half = frame(engine::AreaShadowRes::Half);
  ASSERT_EQ(full.width, kSize);
  ASSERT_EQ(half.width, kSize);
  float peak = 0.0f;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) peak = std::max(peak, red(full, x, y));
  ASSERT_GT(peak, 0.0f);
  std::vector<float> diffs;
  int outside = 0;
  float worst_outside = 0.0f;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float h = red(half, x, y);
      const float f = red(full, x, y);
      diffs.push_back(std::abs(h - f) / peak);
      float lo = f, hi = f;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int qx = std::clamp(x + dx, 0, kSize - 1), qy = std::clamp(y + dy, 0, kSize - 1);
          lo = std::min(lo, red(full, qx, qy));
          hi = std::max(hi, red(full, qx, qy));
        }
      const float beyond = std::max(lo - h, h - hi) / peak;
      if (beyond > 0.02f) {
        ++outside;
        worst_outside = std::max(worst_outside, beyond);
      }
    }
  std::sort(diffs.begin(), diffs.end());
  const float p95 = diffs[diffs.size() * 95 / 100];
  const float max_diff = diffs.back();
  std::printf(
      "half vs full resolution area shadows: max %.4f, p95 %.5f of the peak; %d pixels beyond their "
      "neighbourhood's range (worst %.4f)\n",
      static_cast<double>(max_diff), static_cast<double>(p95), outside, static_cast<double>(worst_outside));
  EXPECT_EQ(outside, 0) << "worst " << worst_outside << " of the peak beyond the 5x5 neighbourhood's range";
  EXPECT_LT(p95, 0.01f);
  // The largest difference is at the sharpest penumbrae (contact shadows); a shadow lent across
  // a geometry edge (a lit top over shadowed floor) differs by far more (0.26 of the peak with
  // the surface test removed from area_shadow.frag.glsl).
  EXPECT_LT(max_diff, 0.1f);
  EXPECT_GT(max_diff, 0.0f) << "the half-resolution path must have run (the frames cannot be identical)";

  // The penumbra: pixels whose light is between 10% and 90% of what they get without the
  // casters (the floor alone), as many (within 10%) in both.
  const engine::ImageRgbaF open = frame(engine::AreaShadowRes::Full, false);
  ASSERT_EQ(open.width, kSize);
  int between_full = 0, between_half = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float o = red(open, x, y);
      if (o < 0.05f * peak) continue;
      const float f = red(full, x, y) / o, h = red(half, x, y) / o;
      between_full += f > 0.1f && f < 0.9f ? 1 : 0;
      between_half += h > 0.1f && h < 0.9f ? 1 : 0;
    }
  std::printf("penumbra pixels (10-90%% of the open floor's light): full %d, half %d\n", between_full, between_half);
  EXPECT_GT(between_full, kSize * kSize / 50) << "the scene must have a penumbra";
  EXPECT_NEAR(static_cast<double>(between_half), static_cast<double>(between_full), 0.1 * between_full);
}
