// The split truth of the light atlas (gi/src/sweep/atlas_split_truth.h) on fields small
// enough to work out by hand: stacking, the mean of two estimates and its noise, the
// indirect-dominated texels, and the two measures with the truth's noise removed.
#include "sweep/atlas_split_truth.h"

#include <gtest/gtest.h>
#include <engine/sun.h>

#include <cmath>
#include <string>
#include <vector>

#include "sweep/sweep_runner.h"
#include "sweep/sweep_scene.h"

namespace {

// A 1-row field of grey texels (R = G = B = value).
gi::RgbField row(const std::vector<float>& values) {
  gi::RgbField f;
  f.width = static_cast<int>(values.size());
  f.height = 1;
  for (float v : values) f.rgb.insert(f.rgb.end(), {v, v, v});
  return f;
}

double extra(const std::vector<std::pair<std::string, double>>& extras, const std::string& name) {
  for (const auto& [n, v] : extras)
    if (n == name) return v;
  ADD_FAILURE() << "no extra " << name;
  return std::nan("");
}

}  // namespace

TEST(AtlasSplitTruth, StackThenUnstackGivesBothHalvesBack) {
  gi::RgbField indirect = row({1, 2, 3});
  gi::RgbField total = row({4, 5, 6});
  indirect.valid = {1, 0, 1};
  total.valid = {1, 0, 1};
  indirect.variance.assign(9, 0.5f);
  total.variance.assign(9, 0.25f);
  const gi::RgbField stacked = gi::stack_split_truth(indirect, total);
  EXPECT_EQ(stacked.width, 3);
  EXPECT_EQ(stacked.height, 2);
  ASSERT_TRUE(stacked.consistent());
  const gi::AtlasSplitTruth back = gi::unstack_split_truth(stacked);
  EXPECT_EQ(back.indirect.rgb, indirect.rgb);
  EXPECT_EQ(back.total.rgb, total.rgb);
  EXPECT_EQ(back.total.valid, total.valid);
  EXPECT_EQ(back.indirect.variance, indirect.variance);
  EXPECT_EQ(back.total.variance, total.variance);
}

TEST(AtlasSplitTruth, MeanOfTwoEstimatesTakesItsNoiseFromTheirDifference) {
  gi::RgbField a = row({1, 5});
  gi::RgbField b = row({3, 5});
  b.valid = {1, 0};
  const gi::RgbField m = gi::mean_of_two_estimates(a, b);
  EXPECT_FLOAT_EQ(m.rgb[0], 2.0f);
  EXPECT_FLOAT_EQ(m.variance[0], 1.0f) << "(1 - 3)^2 / 4";
  EXPECT_FLOAT_EQ(m.variance[3], 0.0f) << "equal estimates";
  EXPECT_EQ(m.valid, (std::vector<std::uint8_t>{1, 0})) << "valid where both are";
  // With their own variances, the mean's is their sum over 4 (independent estimates).
  a.variance.assign(6, 0.4f);
  b.variance.assign(6, 0.8f);
  EXPECT_FLOAT_EQ(gi::mean_of_two_estimates(a, b).variance[0], 0.3f);
}

TEST(AtlasSplitTruth, IndirectDominatedTexelsHaveAtLeast80PercentOfTheirTotalIndirect) {
  gi::AtlasSplitTruth truth{.indirect = row({8, 7.9f, 10, 9, 0}), .total = row({10, 10, 10, 10, 0})};
  truth.total.valid = {1, 1, 1, 0, 1};
  truth.indirect.valid = truth.total.valid;
  EXPECT_EQ(gi::indirect_dominated_mask(truth), (std::vector<std::uint8_t>{1, 0, 1, 0, 0}))
      << "80% is in, 79% out; an invalid texel and a black one are never selected";
  EXPECT_EQ(gi::indirect_dominated_mask(truth, 0.5), (std::vector<std::uint8_t>{1, 1, 1, 0, 0}));
  // The per-texel predicate the breakdown shares: a texel the truth leaves dark is not selected
  // (0 >= 0.8 x 0 would be).
  EXPECT_FALSE(gi::is_indirect_dominated(0.0, 0.0));
  EXPECT_TRUE(gi::is_indirect_dominated(0.8, 1.0));
}

TEST(AtlasSplitTruth, MeasuresTheIndirectDominatedTexelsAndTheWholeLightmapApart) {
  // Texels 0, 1 lit by a bounce, 2, 3 directly; the method is 10% high on the first two only.
  gi::AtlasSplitTruth truth{.indirect = row({9, 9, 1, 1}), .total = row({10, 10, 10, 10})};
  truth.total.variance.assign(12, 0.0f);
  const gi::RgbField method = row({11, 11, 10, 10});
  const auto e = gi::split_truth_extras(method, truth);
  EXPECT_NEAR(extra(e, "indirect_dominated"), 0.1, 1e-9);
  EXPECT_NEAR(extra(e, "indirect_dominated_share"), 0.5, 1e-12);
  EXPECT_NEAR(extra(e, "whole"), std::sqrt(2.0 * 1.0 / (4.0 * 100.0)), 1e-9);
  EXPECT_NEAR(extra(e, "whole_bias"), 0.05, 1e-9) << "(11 + 11 + 10 + 10) / 40 - 1";
}

TEST(AtlasSplitTruth, RemovesTheTruthsNoiseOnTheIndirectDominatedTexels) {
  // The truth's estimate is the noise-free 10 off by exactly one standard deviation (+-1,
  // variance 1) on every texel; a method that is the noise-free truth scores 0 error, though
  // its plain relative RMSE against the estimate is 10%.
  gi::AtlasSplitTruth truth{.indirect = row({9, 9, 9, 9, 0, 0}), .total = row({11, 9, 11, 9, 11, 9})};
  truth.total.variance.assign(18, 1.0f);
  const gi::RgbField exact = row({10, 10, 10, 10, 10, 10});
  const auto e = gi::split_truth_extras(exact, truth);
  EXPECT_NEAR(extra(e, "indirect_dominated"), 0.0, 1e-9);
  EXPECT_NEAR(extra(e, "whole"), 0.0, 1e-9);
  // One 20% high on the selected texels: its error from the truth is about 20%, not the
  // 20% + noise a plain comparison would give.
  const gi::RgbField high = row({12, 12, 12, 12, 10, 10});
  EXPECT_NEAR(gi::split_truth_extras(high, truth)[0].second, 0.2, 0.03);
}

TEST(AtlasSplitTruth, NoIndirectDominatedTexelsIsNaNNotZero) {
  gi::AtlasSplitTruth truth{.indirect = row({1, 1}), .total = row({10, 10})};
  truth.total.variance.assign(6, 0.0f);
  const auto e = gi::split_truth_extras(row({10, 10}), truth);
  EXPECT_TRUE(std::isnan(extra(e, "indirect_dominated")));
  EXPECT_EQ(extra(e, "indirect_dominated_share"), 0.0);
  EXPECT_NEAR(extra(e, "whole"), 0.0, 1e-12);
}

// The harness's side (sweep_runner.h): with split_truth_spp the runs are judged against the
// method's split truth, their main error against its indirect half, and they see the whole.
namespace {

struct SplitWorld {
  int provider_calls = 0;
  gi::SweepRegistry registry;
  SplitWorld() {
    registry.add_reference_provider(
        {.kind = "split_test", .version = "test-1", .compute = [this](const gi::ReferenceJob& job) {
           ++provider_calls;
           EXPECT_EQ(job.request.param("spp"), "4");
           gi::RgbField indirect = row({9, 9, 1, 1}), total = row({10, 10, 10, 10});
           indirect.variance.assign(12, 0.0f);
           total.variance.assign(12, 0.0f);
           return engine::Result<gi::RgbField>(gi::stack_split_truth(indirect, total));
         }});
    gi::SweepMethod m;
    m.name = "split_method";
    m.reference_for = [](const gi::SweepScene&, const gi::KnobSetting&) {
      return gi::ReferenceRequest{"no_such_kind", {}};
    };
    m.split_truth_for = [](const gi::SweepScene&, const gi::KnobSetting&, int spp) {
      return gi::ReferenceRequest{"split_test", {{"spp", std::to_string(spp)}}};
    };
    m.run = [](const gi::RunContext& ctx) -> engine::Result<gi::MethodOutput> {
      EXPECT_NE(ctx.split_truth, nullptr);
      gi::MethodOutput out;
      out.field = ctx.reference;  // the indirect half, exactly
      if (ctx.split_truth)
        out.extras = gi::split_truth_extras(row({11, 11, 10, 10}), gi::unstack_split_truth(*ctx.split_truth));
      return out;
    };
    registry.add_method(std::move(m));
  }
};

}  // namespace

TEST(AtlasSplitTruth, TheSweepJudgesRunsAgainstTheIndirectHalfAndReportsTheMeasures) {
  SplitWorld world;
  gi::SweepScene scene;
  scene.content_hash = "0000000000000000";
  const gi::KnobSetting no_knobs;
  const std::vector<gi::KnobSetting> settings{no_knobs, no_knobs};
  auto result = gi::run_sweep(world.registry, *world.registry.find_method("split_method"), scene, settings,
                              {.split_truth_spp = 4});
  ASSERT_TRUE(result.ok()) << result.error().to_string();
  ASSERT_EQ(result->rows.size(), 2u);
  EXPECT_EQ(world.provider_calls, 1) << "one truth for both runs";
  const gi::SweepRow& r = result->rows[0];
  EXPECT_TRUE(r.ok()) << r.status;
  EXPECT_EQ(r.reference_key.find("split_test(spp=4)") != std::string::npos, true) << r.reference_key;
  EXPECT_NEAR(r.error.rel_rmse, 0.0, 1e-12) << "the main error is against the indirect half";
  EXPECT_NEAR(extra(r.extras, "indirect_dominated"), 0.1, 1e-9);
  EXPECT_NEAR(extra(r.extras, "whole_bias"), 0.05, 1e-9);
}

TEST(AtlasSplitTruth, AMethodWithoutASplitTruthIsAnError) {
  SplitWorld world;
  gi::SweepMethod plain = *world.registry.find_method("split_method");
  plain.split_truth_for = nullptr;
  gi::SweepScene scene;
  scene.content_hash = "0000000000000000";
  const std::vector<gi::KnobSetting> settings{gi::KnobSetting{}};
  auto result = gi::run_sweep(world.registry, plain, scene, settings, {.split_truth_spp = 4});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().to_string().find("split truth"), std::string::npos) << result.error().to_string();
}

// The lighting gi-sweep --sky / --sun / --untextured give the scene is in its fingerprint, so
// a truth cached under other lighting is never reused.
TEST(AtlasSplitTruth, SkyAndSunChangeTheSceneFingerprint) {
  auto scene = gi::load_sweep_scene(std::filesystem::path(GI_SOURCE_DIR) / "assets" / "cornell_box.gltf");
  ASSERT_TRUE(scene.ok()) << scene.error().to_string();
  engine::SceneAsset lit = scene->asset;
  lit.environment.sky_gradient.zenith = glm::vec3(10.0f, 16.0f, 30.0f);
  const std::string plain = gi::scene_fingerprint(scene->path, scene->asset).value();
  const std::string sky = gi::scene_fingerprint(scene->path, lit).value();
  EXPECT_NE(plain, sky);
  engine::set_sun(lit, {.direction = {0.25f, -1.0f, 0.15f}, .irradiance = glm::vec3(700.0f)});
  EXPECT_NE(gi::scene_fingerprint(scene->path, lit).value(), sky);
}
