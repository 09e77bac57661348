// The sky in a PRM bake (docs/prm.md "The sky"): the sky is a static source, so it lives in
// the light atlas the PRM provider composes with. A PRM asked for alone on a sky-lit scene
// bakes that atlas too, and the provider's atlas (the sky's direct light and bounces + the
// moving lamp's bounces) matches the path tracer's: its indirect irradiance under both, plus
// the sky's direct irradiance (which the atlas holds: the renderer draws no sky on the static
// world then, docs/scene-format.md).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/error_metrics.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "gl_readback.h"
#include "light_atlas/light_atlas_io.h"
#include "prm/prm_io.h"
#include "raytrace/atlas_reference.h"
#include "system/prm_lighting.h"
#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace fs = std::filesystem;

namespace {

// The Cornell box (open at the front) under a sky, its lamp a moving light without its glowing
// quad (the path tracer would take an emissive quad over the lamp for the lamp itself), 1 cm
// below the ceiling it sits in (else the ceiling hides it from the path tracer's shadow rays).
engine::Scene sky_lit_cornell_box_with_moving_lamp(glm::vec3 sky) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset) << asset.error().to_string();
  engine::SceneAsset a = std::move(asset).value();
  for (engine::Node& n : a.nodes)
    if (n.name == "light_quad") n.mesh = -1;
  a.environment.sky_radiance = sky;
  engine::Scene scene = engine::instantiate(std::move(a));
  const engine::Entity lamp = engine::find_by_name(scene.registry, "light");
  EXPECT_FALSE(lamp.is_null());
  scene.registry.write<engine::Light>(lamp).moves = true;
  scene.registry.write<engine::WorldTransform>(lamp).matrix[3].y -= 0.01f;
  return scene;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".gibake");
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST(PrmSky, APrmBakeOfASkyLitSceneCarriesTheSkyInItsAtlasAndMatchesThePathTracer) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  engine::Scene scene = sky_lit_cornell_box_with_moving_lamp(glm::vec3(0.8f, 0.9f, 1.0f));
  const gi::BakeInput input = gi::bake_input_from(scene);
  const fs::path dir = fresh_dir("gi_prm_sky");
  auto report = gi::bake_bundle(input, dir, {.preset = "medium", .methods = {"prm"}, .texels_per_metre = 32.0f});
  ASSERT_TRUE(report) << report.error().to_string();
  ASSERT_EQ(report->baked.size(), 2u);
  EXPECT_EQ(report->baked[0].method, "light_atlas") << "the sky's light atlas, baked before the PRM";
  EXPECT_EQ(report->baked[1].method, "prm");

  auto atlas = gi::load_light_atlas(dir, input);
  ASSERT_TRUE(atlas) << atlas.error().to_string();
  auto prm = gi::load_prm(dir, input);
  ASSERT_TRUE(prm) << prm.error().to_string();
  // The atlas the PRM is read at (the medium preset's panes are coarser, issue 38).
  const gi::AtlasLayout layout = prm->atlas_layout();
  const int w = prm->atlas_width(), h = prm->atlas_height();

  // The truth under sky and lamp, and under each alone (the atlas models the one, the PRM the other).
  gi::ReferenceSettings rs;
  rs.samples_per_pixel = 1024;
  rs.seed = 5;
  const gi::AtlasTexels texels = gi::rasterize_atlas(layout, gi::atlas_inputs_from(gi::bake_input_from(scene.assets)));
  gi::BakeInput lamp_only = input;
  lamp_only.environment.sky_radiance = glm::vec3(0.0f);
  gi::BakeInput sky_only = input;
  for (gi::BakeLight& l : sky_only.lights) l.light.enabled = false;
  const auto truth = [&](const gi::BakeInput& in) {
    auto t = gi::reference_atlas_irradiance(in, texels, rs);
    EXPECT_TRUE(t) << t.error().to_string();
    return std::move(t).value();
  };
  const gi::AtlasIrradiance t_both = truth(input), t_lamp = truth(lamp_only), t_sky = truth(sky_only);
  // What the composed atlas holds: every light's indirect irradiance and the sky's direct.
  const auto field = [&](const gi::AtlasIrradiance& indirect, const gi::AtlasIrradiance* sky_direct) {
    std::vector<glm::vec3> v = indirect.indirect;
    if (sky_direct)
      for (std::size_t i = 0; i < v.size(); ++i) v[i] += sky_direct->direct[i];
    return gi::RgbField::from_texels(indirect.width, indirect.height, v, indirect.valid);
  };
  const gi::RgbField both = field(t_both, &t_sky), lamp = field(t_lamp, nullptr), sky = field(t_sky, &t_sky);

  const auto provider_atlas = [&](const gi::LightAtlasBake* base) {
    auto p = gi::PrmLighting::from_bake(*prm, base, scene, {.active_clusters = 0});
    EXPECT_TRUE(p) << p.error().to_string();
    return gltest::read_texture((*p)->frame().irradiance_atlas_texture, w, h);
  };
  const std::vector<glm::vec3> composed = provider_atlas(&*atlas), prm_only = provider_atlas(nullptr);
  const gi::ErrorReport with_sky = gi::compare_rgb(gi::RgbField::from_texels(w, h, composed, texels.valid), both);
  const gi::ErrorReport prm_alone = gi::compare_rgb(gi::RgbField::from_texels(w, h, prm_only, texels.valid), both);
  const gi::ErrorReport sky_part =
      gi::compare_rgb(gi::RgbField::from_texels(w, h, atlas->irradiance, texels.valid), sky);
  const gi::ErrorReport lamp_part = gi::compare_rgb(gi::RgbField::from_texels(w, h, prm_only, texels.valid), lamp);
  std::printf(
      "sky-lit Cornell box + moving lamp, medium preset at 32 texels/m, indirect + the sky's direct "
      "irradiance, rel RMSE (scale fit):\n"
      "  light atlas + PRM vs sky + lamp %.4f (%.4f); PRM without the atlas vs sky + lamp %.4f (%.4f)\n"
      "  its parts: atlas vs the sky alone %.4f (%.4f), PRM vs the lamp alone %.4f (%.4f)\n",
      with_sky.rel_rmse, with_sky.fit_scale, prm_alone.rel_rmse, prm_alone.fit_scale, sky_part.rel_rmse,
      sky_part.fit_scale, lamp_part.rel_rmse, lamp_part.fit_scale);
  // Measured: 0.150 (scale 1.047); the parts 0.180 (sky, atlas) and 0.221 (lamp, PRM; the
  // spot chamber's medium-preset class, docs/prm.md); the PRM alone 0.617 (scale 2.19). With
  // the medium preset's coarse panes (16 texels/m read at 32, issue 38; Nov 29): 0.116 (1.013),
  // the parts 0.115 and 0.216 (lamp, PRM), the PRM alone 0.869 (3.09).
  EXPECT_LT(with_sky.rel_rmse, 0.2);
  EXPECT_NEAR(with_sky.fit_scale, 1.0, 0.1);
  EXPECT_LT(sky_part.rel_rmse, 0.25) << "the sky's share is the atlas's";
  EXPECT_NEAR(sky_part.fit_scale, 1.0, 0.1);
  EXPECT_GT(prm_alone.rel_rmse, 2.0 * with_sky.rel_rmse) << "the sky is a large share of this scene's light";
  fs::remove_all(dir);
}

TEST(PrmSky, APrmBakeWithoutASkyBakesNoAtlas) {
  engine::Scene scene = sky_lit_cornell_box_with_moving_lamp(glm::vec3(0.0f));
  const fs::path dir = fresh_dir("gi_prm_no_sky");
  auto report = gi::bake_bundle(gi::bake_input_from(scene), dir,
                                {.preset = "preview", .methods = {"prm"}, .texels_per_metre = 8.0f});
  ASSERT_TRUE(report) << report.error().to_string();
  ASSERT_EQ(report->baked.size(), 1u);
  EXPECT_EQ(report->baked[0].method, "prm");
  fs::remove_all(dir);
}
