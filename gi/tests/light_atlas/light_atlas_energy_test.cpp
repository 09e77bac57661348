// The light-atlas baker's energy bookkeeping in a closed box: the multi-bounce series.
#include <gtest/gtest.h>
#include <engine/scene.h>

#include <cstdio>
#include <numbers>

#include "light_atlas/light_atlas.h"
#include "light_atlas_scenes.h"
#include "raytrace/scene_adapter.h"
#include "transport/vpl_set.h"

namespace {

// A closed box of albedo rho around a point light of power Phi = 4 pi I: all light lands on
// the walls, so the reflected power of all bounces is Phi rho / (1 - rho) (rho: the
// material's hemispherical albedo, Lambert + the renderer's GGX lobe).
TEST(LightAtlasEnergy, ClosedBoxMatchesGeometricSeries) {
  for (float base : {0.5f, 0.8f}) {
    const engine::Scene scene = engine::instantiate(latest::closed_box(2.0f, base, {0.3f, -0.2f, 0.1f}, 5.0f));
    const double rho =
        double{engine::gltf_hemispherical_albedo(gi::reference_material(gi::bake_input_from(scene).materials[0]).brdf)
                   .sum()
                   .y};
    gi::LightAtlasSettings s;
    s.texels_per_metre = 8.0f;
    s.vpl_count = 600;
    s.bounces = 64;
    s.unshot_threshold = 0.0f;
    auto bake = gi::bake_light_atlas(gi::bake_input_from(scene), s);
    ASSERT_TRUE(bake) << bake.error().to_string();
    double reflected = 0.0;
    for (const glm::vec3& e : bake->vpl_power) reflected += static_cast<double>(e.y);
    const double phi = 4.0 * std::numbers::pi * 5.0;
    const double expected = phi * rho / (1.0 - rho);
    std::printf("base %.2f rho %.4f: reflected %.4f W, series %.4f W, ratio %.4f\n", double{base}, rho, reflected,
                expected, reflected / expected);
    EXPECT_NEAR(reflected / expected, 1.0, 0.02);
  }
}

}  // namespace
