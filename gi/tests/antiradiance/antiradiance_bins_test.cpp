// The directional bins (octahedral cells with measured solid angles).
#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include "antiradiance/directional_bins.h"
#include "core/random.h"

namespace {

TEST(DirectionalBins, SolidAnglesSumToFourPiAndStayWithinAFactorOfFour) {
  for (int n : {2, 4, 8, 12}) {
    gi::DirectionalBins bins(n);
    ASSERT_EQ(bins.count(), n * n);
    double total = 0.0;
    float lo = 1e9f, hi = 0.0f;
    for (int j = 0; j < bins.count(); ++j) {
      total += static_cast<double>(bins.solid_angle(j));
      lo = std::min(lo, bins.solid_angle(j));
      hi = std::max(hi, bins.solid_angle(j));
    }
    EXPECT_NEAR(total, 4.0 * glm::pi<double>(), 1e-4) << n;
    EXPECT_LT(hi / lo, 4.0f) << n;  // octahedral cells: measured 3.34 at n = 8
    EXPECT_EQ(lo, bins.min_solid_angle());
  }
}

TEST(DirectionalBins, EveryMainDirectionLiesInItsOwnBin) {
  gi::DirectionalBins bins(8);
  for (int j = 0; j < bins.count(); ++j) {
    EXPECT_NEAR(glm::length(bins.direction(j)), 1.0f, 1e-5f);
    EXPECT_EQ(bins.bin_of(bins.direction(j)), j);
  }
}

// The fraction of uniformly random directions landing in a bin is its solid angle / 4 pi.
TEST(DirectionalBins, RandomDirectionsFillBinsInProportionToTheirSolidAngle) {
  gi::DirectionalBins bins(4);
  std::vector<int> count(static_cast<std::size_t>(bins.count()), 0);
  const int samples = 200000;
  for (int i = 0; i < samples; ++i) {
    gi::Pcg32 rng = gi::Pcg32::for_item(3, static_cast<std::uint64_t>(i));
    const float z = 1.0f - 2.0f * rng.next_float();
    const float phi = 2.0f * glm::pi<float>() * rng.next_float();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    ++count[static_cast<std::size_t>(bins.bin_of({r * std::cos(phi), r * std::sin(phi), z}))];
  }
  for (int j = 0; j < bins.count(); ++j) {
    const double expected = static_cast<double>(bins.solid_angle(j)) / (4.0 * glm::pi<double>());
    EXPECT_NEAR(count[static_cast<std::size_t>(j)] / static_cast<double>(samples), expected, 0.004) << j;
  }
}

}  // namespace
