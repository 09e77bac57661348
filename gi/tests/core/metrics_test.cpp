// Error metrics against hand-computed values (gi/src/metrics/error_metrics.h).
#include <gtest/gtest.h>
#include <engine/display_transform.h>
#include <gi/error_metrics.h>

#include <cmath>
#include <limits>
#include <random>

namespace {

gi::RgbField field_of(int w, int h, std::initializer_list<float> rgb) {
  gi::RgbField f;
  f.width = w;
  f.height = h;
  f.rgb = rgb;
  return f;
}

TEST(ErrorMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  gi::RgbField r = field_of(2, 1, {0.1f, 0.5f, 2.0f, 3.0f, 0.0f, 0.25f});
  const gi::ErrorReport e = gi::compare_rgb(r, r);
  ASSERT_TRUE(e.ok()) << e.problem;
  EXPECT_EQ(e.elements_compared, 2u);
  EXPECT_EQ(e.rel_rmse, 0.0);
  EXPECT_EQ(e.max_rel, 0.0);
  EXPECT_TRUE(std::isinf(e.psnr_db) && e.psnr_db > 0.0);
  EXPECT_EQ(e.fit_scale, 1.0);
  EXPECT_EQ(e.fit_rel_rmse, 0.0);
}

TEST(ErrorMetrics, KnownOffsetGivesKnownRelativeRmse) {
  // r = 1 everywhere, a = 1.1: sum (0.1)^2 / sum 1^2 = 0.01 -> rel RMSE 0.1; max rel 0.1.
  const gi::RgbField r = gi::RgbField::filled(2, 2, 1.0f);
  const gi::RgbField a = gi::RgbField::filled(2, 2, 1.1f);
  const gi::ErrorReport e = gi::compare_rgb(a, r);
  ASSERT_TRUE(e.ok()) << e.problem;
  EXPECT_NEAR(e.rel_rmse, 0.1, 1e-6);
  EXPECT_NEAR(e.max_rel, 0.1, 1e-6);
  // Channels are summed: an error in one channel of one element out of 2x3 values.
  gi::RgbField b = r;
  b.rgb[0] = 3.0f;  // error 2 in one of 12 values: sqrt(4 / 12)
  EXPECT_NEAR(gi::relative_rmse(b, r), std::sqrt(4.0 / 12.0), 1e-9);
}

// A noisy reference r = t + n with known variance v: rel RMSE carries the reference's noise,
// truth_rel_rmse removes it and finds the approximation's own 2% error.
TEST(ErrorMetrics, TruthErrorRemovesTheReferencesOwnNoise) {
  constexpr int kW = 100, kH = 60;
  constexpr float kSigma = 0.05f;
  gi::RgbField r = gi::RgbField::filled(kW, kH, 1.0f);
  const gi::RgbField a = gi::RgbField::filled(kW, kH, 1.02f);
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, kSigma);
  for (float& v : r.rgb) v += noise(rng);
  gi::ErrorReport plain = gi::compare_rgb(a, r);
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(std::isnan(plain.truth_rel_rmse));
  EXPECT_TRUE(std::isnan(plain.reference_noise));
  EXPECT_NEAR(plain.rel_rmse, std::sqrt(0.02 * 0.02 + 0.05 * 0.05), 0.003);

  r.variance.assign(r.rgb.size(), kSigma * kSigma);
  const gi::ErrorReport e = gi::compare_rgb(a, r);
  ASSERT_TRUE(e.ok()) << e.problem;
  EXPECT_EQ(e.rel_rmse, plain.rel_rmse);
  EXPECT_NEAR(e.reference_noise, 0.05, 0.002);
  EXPECT_NEAR(e.truth_rel_rmse, 0.02, 0.003);
  // The reference against itself-plus-nothing: the truth error of the truth is ~0.
  gi::RgbField t = gi::RgbField::filled(kW, kH, 1.0f);
  EXPECT_LT(gi::compare_rgb(t, r).truth_rel_rmse, 0.006);
}

TEST(ErrorMetrics, MaxRelativeUsesTheFloorForNearBlackElements) {
  // Element 3 of the reference is black; floor = 0.01 * mean |r| = 0.01 * (3 sqrt3 / 4).
  gi::RgbField r = gi::RgbField::filled(4, 1, 1.0f);
  for (int c = 0; c < 3; ++c) r.rgb[9 + c] = 0.0f;
  gi::RgbField a = r;
  for (int c = 0; c < 3; ++c) a.rgb[9 + c] = 0.01f;
  const double expected = (0.01 * std::sqrt(3.0)) / (0.01 * 0.75 * std::sqrt(3.0));
  EXPECT_NEAR(gi::max_relative_error(a, r), expected, 1e-5);
  EXPECT_NEAR(gi::max_relative_error(a, r, 0.1), expected / 10.0, 1e-6);
}

TEST(ErrorMetrics, MaskExcludesTexels) {
  gi::RgbField r = gi::RgbField::filled(2, 2, 1.0f);
  gi::RgbField a = r;
  for (int c = 0; c < 3; ++c) a.rgb[9 + c] = 100.0f;  // element 3 is wrong...
  a.valid = {1, 1, 1, 0};                             // ...but masked out by the output
  gi::ErrorReport e = gi::compare_rgb(a, r);
  ASSERT_TRUE(e.ok()) << e.problem;
  EXPECT_EQ(e.elements_compared, 3u);
  EXPECT_EQ(e.rel_rmse, 0.0);
  a.valid.clear();
  r.valid = {1, 1, 1, 0};  // the reference's mask counts too
  e = gi::compare_rgb(a, r);
  EXPECT_EQ(e.elements_compared, 3u);
  EXPECT_EQ(e.rel_rmse, 0.0);
  r.valid.clear();
  EXPECT_GT(gi::compare_rgb(a, r).rel_rmse, 1.0);
}

TEST(ErrorMetrics, EmptyMaskIsReportedNotZero) {
  gi::RgbField r = gi::RgbField::filled(2, 1, 1.0f);
  r.valid = {0, 0};
  const gi::ErrorReport e = gi::compare_rgb(r, r);
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.elements_compared, 0u);
  EXPECT_TRUE(std::isnan(e.rel_rmse));
  EXPECT_NE(e.problem.find("no element"), std::string::npos) << e.problem;
}

TEST(ErrorMetrics, BlackReferenceIsReported) {
  const gi::RgbField r = gi::RgbField::filled(2, 1, 0.0f);
  const gi::ErrorReport e = gi::compare_rgb(gi::RgbField::filled(2, 1, 1.0f), r);
  EXPECT_FALSE(e.ok());
  EXPECT_NE(e.problem.find("zero"), std::string::npos) << e.problem;
}

TEST(ErrorMetrics, ScaleFitRecoversTwoForHalfImage) {
  gi::RgbField r = field_of(3, 1, {0.3f, 1.7f, 2.9f, 0.01f, 5.5f, 1.0f, 7.25f, 0.125f, 0.8f});
  gi::RgbField a = r;
  for (float& v : a.rgb) v /= 2.0f;
  const gi::ErrorReport e = gi::compare_rgb(a, r);
  ASSERT_TRUE(e.ok()) << e.problem;
  EXPECT_EQ(e.fit_scale, 2.0);
  EXPECT_EQ(e.fit_rel_rmse, 0.0);
  EXPECT_EQ(e.fit_max_rel, 0.0);
  EXPECT_TRUE(std::isinf(e.fit_psnr_db));
  EXPECT_NEAR(e.rel_rmse, 0.5, 1e-9);  // |a - r| = |r| / 2 everywhere
  EXPECT_EQ(gi::least_squares_scale(gi::RgbField::filled(3, 1, 0.0f), r), 1.0);
}

TEST(ErrorMetrics, NaNAndInfInputsAreCountedAndReported) {
  const gi::RgbField r = gi::RgbField::filled(2, 2, 1.0f);
  gi::RgbField a = r;
  a.rgb[4] = std::numeric_limits<float>::quiet_NaN();
  a.rgb[7] = std::numeric_limits<float>::infinity();
  gi::ErrorReport e = gi::compare_rgb(a, r);
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.nonfinite_approx, 2u);
  EXPECT_EQ(e.nonfinite_reference, 0u);
  EXPECT_TRUE(std::isnan(e.rel_rmse));
  EXPECT_TRUE(std::isnan(e.max_rel));
  EXPECT_TRUE(std::isnan(e.psnr_db));
  EXPECT_NE(e.problem.find("non-finite"), std::string::npos) << e.problem;
  // The single metrics never drop a NaN either (std::max would).
  EXPECT_TRUE(std::isnan(gi::relative_rmse(a, r)));
  EXPECT_TRUE(std::isnan(gi::max_relative_error(a, r)));
  EXPECT_TRUE(std::isnan(gi::tonemapped_psnr_db(a, r)));
  // Reference side is counted separately.
  e = gi::compare_rgb(r, a);
  EXPECT_EQ(e.nonfinite_reference, 2u);
  EXPECT_FALSE(e.ok());
  // A NaN in a masked-out element is not compared.
  a.valid = {1, 0, 0, 1};
  e = gi::compare_rgb(a, r);
  EXPECT_TRUE(e.ok()) << e.problem;
}

TEST(ErrorMetrics, PsnrOfTonemappedImages) {
  // 1000 tonemaps to exactly 1 (ACES fit clamps), 0 to 0: one of two elements fully wrong
  // gives MSE 0.5 -> 10 log10(2) dB.
  EXPECT_NEAR(engine::display_tonemap(1000.0, 1.0), 1.0, 1e-12);
  EXPECT_EQ(engine::display_tonemap(0.0, 1.0), 0.0);
  EXPECT_EQ(engine::display_tonemap(-5.0, 1.0), 0.0);
  const gi::RgbField r = field_of(2, 1, {1000.0f, 1000.0f, 1000.0f, 0.0f, 0.0f, 0.0f});
  const gi::RgbField a = gi::RgbField::filled(2, 1, 0.0f);
  EXPECT_NEAR(gi::tonemapped_psnr_db(a, r), 10.0 * std::log10(2.0), 1e-9);
  // Exposure scales before the curve: 0.18 at exposure 2 tonemaps like 0.36.
  EXPECT_DOUBLE_EQ(engine::display_tonemap(0.18, 2.0), engine::display_tonemap(0.36, 1.0));
  // Matches the shader's curve at a mid-grey value.
  const double x = 0.18;
  const double aces = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
  EXPECT_NEAR(engine::display_tonemap(0.18, 1.0), 1.055 * std::pow(aces, 1.0 / 2.4) - 0.055, 1e-12);
}

TEST(ErrorMetricsDeathTest, DifferentLayoutsAreAProgrammerError) {
  const gi::RgbField a = gi::RgbField::filled(2, 2, 1.0f);
  const gi::RgbField b = gi::RgbField::filled(4, 1, 1.0f);
  EXPECT_DEATH((void)gi::compare_rgb(a, b), "same width and height");
  gi::RgbField c = a;
  c.valid = {1, 1};
  EXPECT_DEATH((void)gi::compare_rgb(c, a), "rgb/valid sizes");
}

}  // namespace
