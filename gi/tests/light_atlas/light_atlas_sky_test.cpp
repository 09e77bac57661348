// A light atlas lit by the sky alone (BakeInput::environment, the glTF scene's gi.sky):
// the Cornell box without its lamp, open at the front under a uniform sky. The final gather
// counts escaped rays as sky light; the bake must match the reference path tracer, whose
// escaped paths return the sky radiance.
#include <engine/gltf.h>
#include <gi/error_metrics.h>
#include <gtest/gtest.h>

#include <cstdio>

#include "light_atlas/light_atlas.h"
#include "raytrace/atlas_reference.h"
#include "raytrace/texel_samples.h"
#include "uv/atlas_layout.h"

namespace {

gi::BakeInput sky_lit_cornell_box(glm::vec3 sky) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset) << asset.error().to_string();
  engine::SceneAsset a = std::move(asset).value();
  for (engine::Node& n : a.nodes) n.light = -1;  // no lamp
  a.lights.clear();
  for (engine::Material& m : a.materials) m.emissive = glm::vec3(0.0f);  // no glowing quad
  a.environment.sky_radiance = sky;
  return gi::bake_input_from(a);
}

}  // namespace

// Medium preset at 64 texels/m against 1024 samples per texel at the same texel samples,
// total irradiance (the sky seen directly + its bounces).
TEST(LightAtlasSky, BakeUnderTheSkyMatchesThePathTracer) {
  const glm::vec3 sky(0.8f, 0.9f, 1.0f);
  const gi::BakeInput input = sky_lit_cornell_box(sky);
  gi::LightAtlasSettings s = gi::light_atlas_preset("medium").value();
  s.texels_per_metre = 64.0f;
  s.include_direct = true;
  auto bake = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(bake) << bake.error().to_string();

  auto layout = gi::static_world_layout(input, s.texels_per_metre);
  ASSERT_TRUE(layout);
  auto texels = gi::sample_atlas_texels(input, *layout, gi::texel_placement(s));
  ASSERT_TRUE(texels);
  gi::ReferenceSettings rs;
  rs.samples_per_pixel = 1024;
  rs.seed = 5;
  auto truth = gi::reference_atlas_irradiance(input, *texels, rs);
  ASSERT_TRUE(truth) << truth.error().to_string();

  double lit = 0.0;
  for (std::size_t t = 0; t < truth->total.size(); ++t) lit += truth->valid[t] ? static_cast<double>(truth->total[t].y) : 0.0;
  ASSERT_GT(lit, 0.0) << "the sky reaches nothing in the reference";
  const gi::ErrorReport e =
      gi::compare_rgb(gi::RgbField::from_texels(bake->width, bake->height, bake->irradiance, bake->valid),
                      gi::RgbField::from_texels(truth->width, truth->height, truth->total, truth->valid));
  std::printf("sky-lit Cornell box, medium preset at 64 texels/m: rel RMSE %.4f (scale fit %.4f), bake %.2f s\n",
              e.rel_rmse, e.fit_scale, bake->stats.total_seconds);
  EXPECT_LT(e.rel_rmse, 0.08);
  EXPECT_NEAR(e.fit_scale, 1.0, 0.03);
}
