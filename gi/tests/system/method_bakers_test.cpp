// The bake's method table (bake/method_bakers.h): one baker per method of gi/methods.h, in
// the order bakes run (the atlas methods before antiradiance, which stores its texel blends
// for the atlas already in the bundle), and gi-bake's --methods list follows it.
#include <gtest/gtest.h>
#include <gi/bake.h>
#include <gi/methods.h>

#include <algorithm>
#include <string>
#include <vector>

#include "bake/method_bakers.h"

namespace {

std::size_t position(gi::EffectMethod m) {
  const auto rows = gi::method_bakers();
  return static_cast<std::size_t>(
      std::find_if(rows.begin(), rows.end(), [&](const gi::MethodBakerEntry& e) { return e.method == m; }) -
      rows.begin());
}

TEST(MethodBakers, EveryMethodHasOneBakerAndTheAtlasMethodsComeBeforeAntiradiance) {
  const auto rows = gi::method_bakers();
  EXPECT_EQ(rows.size(), gi::kMethods.size());
  for (const gi::MethodDescriptor& d : gi::kMethods) {
    EXPECT_EQ(
        std::count_if(rows.begin(), rows.end(), [&](const gi::MethodBakerEntry& e) { return e.method == d.method; }), 1)
        << d.key;
    EXPECT_EQ(gi::method_baker(d.method).method, d.method) << d.key;
    EXPECT_NE(gi::method_baker(d.method).bake, nullptr) << d.key;
  }
  EXPECT_LT(position(gi::EffectMethod::LightAtlas), position(gi::EffectMethod::Antiradiance));
  EXPECT_LT(position(gi::EffectMethod::Prm), position(gi::EffectMethod::Antiradiance));
}

TEST(MethodBakers, BakeableMethodsAreTheTablesKeysInItsOrder) {
  std::vector<std::string> keys;
  for (const gi::MethodBakerEntry& e : gi::method_bakers()) keys.emplace_back(gi::method_descriptor(e.method).key);
  EXPECT_EQ(gi::bakeable_methods(), keys);
}

}  // namespace
