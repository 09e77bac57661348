// The glossy sweeps' eye above the glossy floor (GlossyView::Above): the demo corridor's floor,
// which camera 0 sees only at grazing through the doorway, is then measured in the steeper
// view bands too (docs/dlm.md, "The corridor's grazing band").
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "sweep/glossy_texels.h"
#include "sweep/sweep_scene.h"

namespace fs = std::filesystem;

namespace {

// Smallest and largest cos(theta_v) over the glossy floor texels (normal up) a view sees, and
// their count (at roughness 0.5 a few texels under the crate room's light are glossy too).
struct ViewBands {
  float lo = 2.0f, hi = -2.0f;
  std::size_t texels = 0;
};

ViewBands bands_of(const gi::GlossyTexels& g) {
  ViewBands b;
  const gi::AtlasTexels& tex = g.s.texels;
  for (std::size_t t = 0; t < tex.valid.size(); ++t) {
    if (!g.glossy[t] || !(tex.normal[t].y > 0.9f)) continue;
    const float c = glm::dot(tex.normal[t], glm::normalize(g.eye - tex.position[t]));
    b.lo = std::min(b.lo, c), b.hi = std::max(b.hi, c), ++b.texels;
  }
  return b;
}

TEST(GlossyView, AboveTheCorridorFloorSeesTheBandsCameraZeroDoesNot) {
  auto scene = gi::load_sweep_scene(fs::path(GI_SOURCE_DIR) / "assets" / "demo_level.gltf");
  ASSERT_TRUE(scene) << scene.error().to_string();
  auto camera = gi::glossy_texels(*scene, 4.0, 0.5, nullptr, gi::TexelPlacement::VisibleSurface);
  auto above = gi::glossy_texels(*scene, 4.0, 0.5, nullptr, gi::TexelPlacement::VisibleSurface, gi::GlossyView::Above);
  ASSERT_TRUE(camera) << camera.error().to_string();
  ASSERT_TRUE(above) << above.error().to_string();
  const ViewBands c = bands_of(*camera), a = bands_of(*above);
  // Camera 0 (in the hub, 1.7 m up) sees the corridor floor only at grazing: one band.
  EXPECT_GT(c.texels, 0u);
  EXPECT_LT(c.hi, 0.3f);
  // From above the floor's centre: the same floor, every texel facing the eye, up to straight down.
  EXPECT_EQ(a.texels, c.texels);
  EXPECT_GT(a.hi, 0.95f);
  EXPECT_GT(a.lo, 0.3f);
  // The eye stands on the corridor floor (y = 0, x 3..5, z 8..17), at eye height above the
  // glossy texels' centroid: the grille's (0.6 m up, valid since the cut-out test samples
  // each texel off the grille's hole pattern) lift it a few centimetres.
  EXPECT_GE(above->eye.y, 1.7f);
  EXPECT_LT(above->eye.y, 1.8f);
  EXPECT_GT(above->eye.x, 3.0f);
  EXPECT_LT(above->eye.x, 5.0f);
  EXPECT_GT(above->eye.z, 8.0f);
  EXPECT_LT(above->eye.z, 17.0f);
  // The default view is camera 0, unchanged.
  EXPECT_EQ(camera->eye, glm::vec3(4.0f, 1.7f, 1.0f));
}

}  // namespace
