// The PRM sweep's helpers for large levels (gi/src/sweep/prm_sweep.h): the fixed random
// subset of texels a reference path-traces, the poses that start from the authored light,
// the reference key of a subset, and the swing and world knobs in it.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "light_atlas_scenes.h"
#include "sweep/builtin_methods.h"
#include "sweep/knob_grid.h"
#include "sweep/prm_sweep.h"
#include "sweep_fixtures.h"

namespace {

using sweeptest::make_scene;

gi::AtlasTexels texels_with_valid(const std::vector<std::uint8_t>& valid) {
  gi::AtlasTexels t;
  t.width = static_cast<int>(valid.size());
  t.height = 1;
  t.valid = valid;
  return t;
}

TEST(PrmSweep, RandomTexelSubsetKeepsThatManyValidTexelsTheSameEachTime) {
  std::vector<std::uint8_t> valid(1000, 0);
  for (std::size_t i = 0; i < valid.size(); ++i) valid[i] = (i % 3 != 0) ? 1 : 0;  // 666 valid
  gi::AtlasTexels a = texels_with_valid(valid), b = texels_with_valid(valid);
  gi::keep_random_texels(a, 100);
  gi::keep_random_texels(b, 100);
  EXPECT_EQ(a.valid, b.valid);
  std::size_t kept = 0, low = 0;
  for (std::size_t i = 0; i < valid.size(); ++i) {
    if (a.valid[i] == 0) continue;
    ++kept;
    EXPECT_EQ(valid[i], 1) << "texel " << i << " was not valid";
    if (i < 500) ++low;
  }
  EXPECT_EQ(kept, 100u);
  // Spread over the atlas, not its first texels: about half in each half.
  EXPECT_GT(low, 30u);
  EXPECT_LT(low, 70u);
  gi::AtlasTexels all = texels_with_valid(valid);
  gi::keep_random_texels(all, 666);
  EXPECT_EQ(all.valid, valid);
}

TEST(PrmSweep, Wall20PutsTheLightTwentyCentimetresFromTheNearestWall) {
  // A 4 m box, the light 0.5 m from its +x wall (x = 2) and 1.5 m from +z.
  const engine::SceneAsset box = latest::closed_box(4.0f, 0.5f, {1.5f, 0.0f, 0.5f});
  auto at = gi::moved_light_position(box, {1.5f, 0.0f, 0.5f}, "wall20");
  ASSERT_TRUE(at) << at.error().to_string();
  EXPECT_NEAR(at->x, 1.8f, 1e-4f);
  EXPECT_NEAR(at->y, 0.0f, 1e-6f);
  EXPECT_NEAR(at->z, 0.5f, 1e-6f);
  auto along = gi::moved_light_position(box, {-1.0f, 0.0f, 0.0f}, "along");
  ASSERT_TRUE(along) << along.error().to_string();
  EXPECT_NEAR(along->x, -1.0f + 0.3f * 4.0f, 1e-5f);
  // 10 cm from the wall already: no place 20 cm from it along that line.
  EXPECT_FALSE(gi::moved_light_position(box, {1.9f, 0.0f, 0.0f}, "wall20"));
  EXPECT_FALSE(gi::moved_light_position(box, {0.0f, 0.0f, 0.0f}, "corner"));
}

TEST(PrmSweep, TexelSubsetNamesItselfInTheReferenceKeyOnlyWhenSet) {
  gi::SweepRegistry reg;
  gi::register_builtin_sweep_methods(reg);
  const gi::SweepMethod* prm = reg.find_method("prm");
  ASSERT_NE(prm, nullptr);
  const gi::SweepScene scene;
  const std::vector<std::string> subset = {"pose=wall20", "ref_texels=30000", "ref_spp=1024"};
  auto grid = gi::make_knob_grid(*prm, subset);
  ASSERT_TRUE(grid) << grid.error().to_string();
  ASSERT_EQ(grid->settings().size(), 6u);  // entries x clusters
  EXPECT_EQ(prm->reference_for(scene, grid->settings()[0]).key(),
            "atlas_indirect_irradiance_posed(pose=wall20,spp=1024,texels=30000,texels_per_m=4)");
  const std::vector<std::string> whole = {"pose=along", "ref_texels=0", "entries=256", "clusters=32"};
  auto grid2 = gi::make_knob_grid(*prm, whole);
  ASSERT_TRUE(grid2) << grid2.error().to_string();
  EXPECT_EQ(prm->reference_for(scene, grid2->settings()[0]).key(),
            "atlas_indirect_irradiance_posed(pose=along,spp=4096,texels_per_m=4)");
}

// The PRM's swing and world knobs name themselves in the reference key only when set, so the
// references of unswung, all-instance runs keep the keys (and cache files) they had before.
TEST(BuiltinSweepMethods, PrmSwingAndWorldKeepDefaultReferenceKeys) {
  gi::SweepRegistry reg;
  gi::register_builtin_sweep_methods(reg);
  const gi::SweepMethod* prm = reg.find_method("prm");
  ASSERT_NE(prm, nullptr);
  const gi::SweepScene scene = make_scene();
  const std::vector<std::string> plain = {"entries=256", "clusters=32", "pose=corner"};
  auto grid = gi::make_knob_grid(*prm, plain);
  ASSERT_TRUE(grid) << grid.error().to_string();
  ASSERT_EQ(grid->settings().size(), 1u);
  EXPECT_EQ(prm->reference_for(scene, grid->settings()[0]).key(),
            "atlas_indirect_irradiance_posed(pose=corner,spp=4096,texels_per_m=4)");
  const std::vector<std::string> swung = {"entries=256", "clusters=32", "pose=corner", "swing=-20", "world=static"};
  auto grid2 = gi::make_knob_grid(*prm, swung);
  ASSERT_TRUE(grid2) << grid2.error().to_string();
  EXPECT_EQ(prm->reference_for(scene, grid2->settings()[0]).key(),
            "atlas_indirect_irradiance_posed(pose=corner,spp=4096,swing=-20,texels_per_m=4,world=static)");
  const std::vector<std::string> bad = {"world=some"};
  EXPECT_FALSE(gi::make_knob_grid(*prm, bad));
}

}  // namespace
