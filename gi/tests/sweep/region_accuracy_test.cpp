// The numbers of a frame-vs-truth comparison (gi/src/sweep/region_accuracy.h) on images
// small enough to work out by hand: the luminance bias, its noise from the truth's
// variance, compare_rgb's errors over a mask, and the false-colour ratio image.
#include "sweep/region_accuracy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

engine::ImageRgbaF grey(int w, int h, float v) {
  engine::ImageRgbaF img;
  img.width = w;
  img.height = h;
  img.pixels.assign(static_cast<std::size_t>(4 * w * h), v);
  for (std::size_t i = 3; i < img.pixels.size(); i += 4) img.pixels[i] = 1.0f;
  return img;
}

}  // namespace

TEST(RegionAccuracy, TwiceAsBrightIsABiasOfOneAndARelativeErrorOfOne) {
  const engine::ImageRgbaF truth = grey(2, 2, 0.5f);
  const engine::ImageRgbaF frame = grey(2, 2, 1.0f);
  const std::vector<float> variance(12, 0.0f);
  const std::vector<std::uint8_t> mask(4, 1);
  const gi::RegionAccuracy a = gi::measure_region("all", frame, truth, variance, mask);
  EXPECT_EQ(a.name, "all");
  EXPECT_EQ(a.pixels, 4u);
  EXPECT_NEAR(a.bias, 1.0, 1e-12);
  EXPECT_NEAR(a.frame_luminance, 1.0, 1e-6);  // Rec. 709 weights sum to 1
  EXPECT_NEAR(a.truth_luminance, 0.5, 1e-6);
  EXPECT_NEAR(a.rel_rmse, 1.0, 1e-6);
  EXPECT_NEAR(a.truth_rel_rmse, 1.0, 1e-6) << "no variance: the truth is its estimate";
  EXPECT_EQ(a.bias_noise, 0.0);
  EXPECT_TRUE(a.problem.empty()) << a.problem;
}

TEST(RegionAccuracy, OnlyMaskedPixelsCountAndANaNOutsideTheMaskIsIgnored) {
  engine::ImageRgbaF truth = grey(2, 1, 1.0f);
  engine::ImageRgbaF frame = grey(2, 1, 1.1f);
  frame.pixels[4] = std::numeric_limits<float>::quiet_NaN();  // pixel 1, left out
  truth.pixels[5] = 100.0f;
  const gi::RegionAccuracy a =
      gi::measure_region("left", frame, truth, std::vector<float>(6, 0.0f), std::vector<std::uint8_t>{1, 0});
  EXPECT_EQ(a.pixels, 1u);
  EXPECT_NEAR(a.bias, 0.1, 1e-6);
  EXPECT_NEAR(a.rel_rmse, 0.1, 1e-6);
}

TEST(RegionAccuracy, TheBiasNoiseIsTheTruthsStandardDeviationOverItsSum) {
  // Truth luminance 1 on 4 pixels (sum 4); each channel's variance 0.01, so the luminance
  // variance per pixel is 0.01 (0.2126^2 + 0.7152^2 + 0.0722^2) and the sum's standard
  // deviation sqrt(4 x that); the frame equals the truth (ratio 1).
  const engine::ImageRgbaF truth = grey(2, 2, 1.0f);
  const double per_pixel = 0.01 * (0.2126 * 0.2126 + 0.7152 * 0.7152 + 0.0722 * 0.0722);
  const gi::RegionAccuracy a =
      gi::measure_region("all", truth, truth, std::vector<float>(12, 0.01f), std::vector<std::uint8_t>(4, 1));
  EXPECT_NEAR(a.bias, 0.0, 1e-12);
  EXPECT_NEAR(a.bias_noise, std::sqrt(4.0 * per_pixel) / 4.0, 1e-7);
  EXPECT_NEAR(a.reference_noise, 0.1, 1e-6);  // sqrt(sum v / sum r^2) = sqrt(0.01)
  EXPECT_NEAR(a.truth_rel_rmse, 0.0, 1e-6) << "equal to the estimate: its noise explains all of its error";
}

TEST(RegionAccuracy, NoPixelsOrABlackTruthSayWhyTheNumbersAreMissing) {
  const engine::ImageRgbaF img = grey(2, 2, 0.0f);
  const gi::RegionAccuracy none =
      gi::measure_region("none", img, img, std::vector<float>(12, 0.0f), std::vector<std::uint8_t>(4, 0));
  EXPECT_EQ(none.pixels, 0u);
  EXPECT_TRUE(std::isnan(none.bias));
  EXPECT_FALSE(none.problem.empty());
  const gi::RegionAccuracy black =
      gi::measure_region("black", img, img, std::vector<float>(12, 0.0f), std::vector<std::uint8_t>(4, 1));
  EXPECT_TRUE(std::isnan(black.bias));
  EXPECT_FALSE(black.problem.empty());
}

TEST(RegionAccuracy, RatioImageIsRedWhereTooBrightBlueWhereTooDarkWhiteWhereEqualGreyOnTheSky) {
  gi::FrameTruthReport r;
  r.truth = grey(4, 1, 1.0f);
  r.frame = grey(4, 1, 1.0f);
  r.frame.pixels[0] = r.frame.pixels[1] = r.frame.pixels[2] = 5.0f;  // over 2 stops too bright: clamped
  r.frame.pixels[4] = r.frame.pixels[5] = r.frame.pixels[6] = 0.2f;  // over 2 stops too dark: clamped
  r.region_of_pixel = {0, 0, 0, gi::kBackgroundPixel};
  r.overall.truth_luminance = 1.0;
  const engine::ImageRgba8 img = gi::ratio_image(r, 2.0f);
  ASSERT_EQ(img.pixels.size(), 16u);
  const auto px = [&](int i) {
    return std::vector<int>{img.pixels[4 * i], img.pixels[4 * i + 1], img.pixels[4 * i + 2]};
  };
  EXPECT_EQ(px(0), (std::vector<int>{255, 0, 0}));
  EXPECT_EQ(px(1), (std::vector<int>{0, 0, 255}));
  EXPECT_EQ(px(2), (std::vector<int>{255, 255, 255}));
  EXPECT_EQ(px(3), (std::vector<int>{128, 128, 128}));
}
