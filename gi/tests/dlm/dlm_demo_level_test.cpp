// The demo level's directional light maps: its grille (roughness 0.5, an alpha MASK wire
// mesh of 6.25 cm diamonds) is the surface the plan routes to them (docs/plan.md, "Routing"),
// so the bake must hold texels of it. It held none: the cut-out test's 4 x 4 grid of points
// per texel fell in the mesh's holes at every texel (drop_cut_out_texels).
#include "dlm/dlm.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <gi/bake_input.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace {

TEST(DlmDemoLevel, TheGrillesTexelsAreValidAndGetMaps) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/demo_level.gltf");
  ASSERT_TRUE(asset) << asset.error().to_string();
  const engine::Scene scene = engine::instantiate(std::move(asset).value());
  const gi::BakeInput input = gi::bake_input_from(scene);
  gi::DlmSettings settings = gi::dlm_preset("preview").value();
  settings.glossy_roughness_min = 0.3f;  // beside the reflection probes (bake_dlm_method)
  settings.photons = 200'000;            // enough for deposits; the preview shoots 2 M
  auto layout = gi::static_world_layout(input, settings.texels_per_metre);
  ASSERT_TRUE(layout.ok()) << layout.error().to_string();
  const gi::AtlasTexels raw = gi::rasterize_atlas(*layout, gi::atlas_inputs_from(input));
  auto s = gi::prepare_static_scene(input, *layout, gi::BakeLights::Static);
  ASSERT_TRUE(s.ok()) << s.error().to_string();
  // The texels of the level's surfaces in the maps' range (the grille is the only one) that
  // the rasterizer covers, and how many of them stay valid once cut-out texels are dropped.
  std::size_t in_range = 0, valid = 0;
  for (std::size_t t = 0; t < raw.valid.size(); ++t) {
    if (!raw.valid[t] || raw.mesh[t] < 0) continue;
    const std::uint32_t inst = s->static_instance[static_cast<std::size_t>(raw.mesh[t])];
    const std::uint32_t tri = s->index.instance_first[inst] + static_cast<std::uint32_t>(raw.triangle[t]);
    const float r = std::sqrt(s->scene.materials[s->index.triangles[tri].material].brdf.alpha);
    if (r < settings.glossy_roughness_min || r >= settings.glossy_roughness) continue;
    ++in_range;
    valid += s->texels.valid[t];
  }
  std::printf("demo level at %g texels/m: %zu texels in [%g, %g), %zu valid after the cut-out test\n",
              double{settings.texels_per_metre}, in_range, double{settings.glossy_roughness_min},
              double{settings.glossy_roughness}, valid);
  ASSERT_GT(in_range, 0u);
  // Every 12.5 cm texel of a 0.6 m grille of 6.25 cm diamonds holds wire.
  EXPECT_EQ(valid, in_range);

  auto dlm = gi::bake_dlm(input, settings);
  ASSERT_TRUE(dlm.ok()) << dlm.error().to_string();
  EXPECT_EQ(dlm->stats.glossy_texels, valid);
  EXPECT_GE(dlm->texel_count(), valid);  // and the gutter texels dilation fills
  EXPECT_GT(dlm->stats.deposits, 0u);
  double sum = 0.0;
  for (float x : dlm->radiance) sum += static_cast<double>(x);
  std::printf("  %zu stored texels, %llu deposits, radiance sum %g\n", dlm->texel_count(),
              static_cast<unsigned long long>(dlm->stats.deposits), sum);
  EXPECT_GT(sum, 0.0);
}

}  // namespace
