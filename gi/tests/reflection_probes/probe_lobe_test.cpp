// The probes' lookup of the specular lobe at the actual view (probe_lobe_radiance,
// reflection_probes/probe_cube.h): it keeps a constant environment exactly constant (the
// furnace: the directional albedo applied once), and at a grazing view it follows the GGX lobe
// where the split sum's isotropic lobe, prefiltered with n = v, blurs light across the
// reflection into a dark slot.
#include <gtest/gtest.h>
#include <engine/gltf_brdf.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "reflection_probes/probe_cube.h"
#include "reflection_probes/reflection_probes.h"

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
const glm::vec3 kUp(0.0f, 1.0f, 0.0f);
// A box so large around the probe that, read from its centre, the box projection is the
// direction itself: an environment at infinity.
const glm::vec3 kFarMin(-1e4f), kFarMax(1e4f), kCentre(0.0f);

TEST(ProbeLobe, AConstantCubeReadsAsThatConstantAtEveryViewAndSampleCount) {
  gi::ProbeCube cube = gi::make_probe_cube(16, gi::full_mip_count(16));
  const glm::vec3 value(0.5f, 2.0f, 7.0f);
  for (glm::vec3& t : cube.levels[0]) t = value;
  gi::prefilter_ggx(cube, 32);
  // A dielectric and a coloured metal (per-channel Fresnel weights).
  const engine::GltfBrdf materials[] = {engine::gltf_brdf(glm::vec3(0.5f), 0.0f, 0.1f),
                                        engine::gltf_brdf(glm::vec3(0.9f, 0.6f, 0.2f), 1.0f, 0.3f)};
  for (const engine::GltfBrdf& m : materials)
    for (float cos_v : {1.0f, 0.6f, 0.15f, 0.02f})
      for (int samples : {1, 4, 8, 16, 32, 64}) {
        const glm::vec3 v(std::sqrt(1.0f - cos_v * cos_v), cos_v, 0.0f);
        const glm::vec3 got =
            gi::probe_lobe_radiance(cube, m, kCentre, kUp, v, samples, kCentre, kFarMin, kFarMax, true);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(got[c], value[c], 1e-5f * value[c]) << "cos_v " << cos_v << ", " << samples << " samples";
      }
}

// The count grows with the lobe's stretch: the base count at views along the normal, doubled
// each time cos theta_v halves (the count times n.v reaches the base count), up to the cap; a
// cap at or below the base count keeps it fixed; counts stay within 1..kProbeMaxLobeSamples.
TEST(ProbeLobe, TheSampleCountDoublesAsTheViewGrazesUpToItsCap) {
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 32, 1.0f), 4);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 32, 0.5f), 8);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 32, 0.49f), 16);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 32, 0.25f), 16);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 32, 0.15f), 32);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 32, 0.01f), 32);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 24, 0.01f), 16);  // powers of two of the base, within the cap
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 4, 0.01f), 4);
  EXPECT_EQ(gi::probe_lobe_sample_count(8, 0, 0.01f), 8);
  EXPECT_EQ(gi::probe_lobe_sample_count(0, 0, 1.0f), 1);
  EXPECT_EQ(gi::probe_lobe_sample_count(1000, 1000, 0.0f), gi::kProbeMaxLobeSamples);
  EXPECT_EQ(gi::probe_lobe_sample_count(4, 1000, -1.0f), gi::kProbeMaxLobeSamples);
  // Never fewer samples at a more grazing view.
  int previous = 0;
  for (float nv = 1.0f; nv >= 0.0f; nv -= 0.01f) {
    const int count = gi::probe_lobe_sample_count(4, gi::kProbeGrazingLobeSamples, nv);
    EXPECT_GE(count, previous) << "n.v " << nv;
    EXPECT_GE(static_cast<float>(count) * nv, nv > 4.0f / gi::kProbeGrazingLobeSamples ? 4.0f : 0.0f) << nv;
    previous = count;
  }
}

// The environment at infinity seen from a floor: 1 everywhere but a dark slot (the demo
// corridor's far opening): directions within kSlotDeg of azimuth of +x and below 30 degrees of
// elevation; below the horizon 0.3 (the floor).
constexpr float kSlotDeg = 4.0f;
float slot_environment(const glm::vec3& d) {
  if (d.y < 0.0f) return 0.3f;
  const float azimuth = std::atan2(d.z, d.x) * 180.0f / kPi;
  const float elevation = std::asin(std::clamp(d.y, -1.0f, 1.0f)) * 180.0f / kPi;
  return std::abs(azimuth) < kSlotDeg && elevation < 30.0f ? 0.0f : 1.0f;
}

// slot_environment captured as a probe of `size`^2 faces, prefiltered with 128 samples.
gi::ProbeCube slot_cube(int size) {
  gi::ProbeCube cube = gi::make_probe_cube(size, gi::full_mip_count(size));
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        cube.levels[0][gi::cube_texel_index(f, x, y, size)] =
            glm::vec3(slot_environment(gi::cube_texel_direction(f, x, y, size)));
  gi::prefilter_ggx(cube, 128);
  return cube;
}

// The specular lobe's mean of slot_environment at view v, written independently of the
// lookup: half vectors from D (not the visible normals) at random, weighted by
// gltf_eval_cos's specular / pdf.
float lobe_truth(const engine::GltfBrdf& m, const glm::vec3& v, int samples) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  const glm::vec3 t(1.0f, 0.0f, 0.0f), b(0.0f, 0.0f, 1.0f);
  double sum = 0.0, weight = 0.0;
  for (int i = 0; i < samples; ++i) {
    const float xi = uniform(rng), phi = 2.0f * kPi * uniform(rng);
    const float cos_h = std::sqrt((1.0f - xi) / (1.0f + (m.alpha * m.alpha - 1.0f) * xi));
    const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos_h * cos_h));
    const glm::vec3 h = sin_h * std::cos(phi) * t + sin_h * std::sin(phi) * b + cos_h * kUp;
    const float v_dot_h = glm::dot(v, h);
    if (v_dot_h <= 0.0f) continue;
    const glm::vec3 l = 2.0f * v_dot_h * h - v;
    const float pdf = engine::gltf_ggx_distribution(cos_h, m.alpha) * cos_h / (4.0f * v_dot_h);
    const float w = engine::gltf_eval_cos(m, kUp, v, l).specular.x / pdf;
    sum += static_cast<double>(w * slot_environment(l));
    weight += static_cast<double>(w);
  }
  return static_cast<float>(sum / weight);
}

// At cos(theta_v) = 0.15, roughness 0.2, the view reflected straight into the slot: the true
// lobe is narrow across the reflection's plane and sees mostly the slot's darkness; the split
// sum's isotropic lobe (n = v), as wide across as along, reads the bright sides (0.33 against
// a truth of 0.02). The lookup at the view errs by less than half the split sum's error at 8
// and 16 samples (0.11 and 0.09 when written: what is left is the GGX tails of the prefiltered
// levels it reads, isotropic themselves; 0.040 and 0.019 since the samples read half a level
// finer, kProbeLobeLevelBias).
TEST(ProbeLobe, AtAGrazingViewTheLobeFollowsTheTruthWhereTheSplitSumBlursAcrossTheSlot) {
  const gi::ProbeCube cube = slot_cube(128);
  const float roughness = 0.2f, cos_v = 0.15f;
  const engine::GltfBrdf m = engine::gltf_brdf(glm::vec3(0.5f), 0.0f, roughness);
  const glm::vec3 v(-std::sqrt(1.0f - cos_v * cos_v), cos_v, 0.0f);  // reflection towards +x
  const float truth = lobe_truth(m, v, 200000);
  const float split_sum =
      gi::cube_lookup_trilinear(cube, roughness * static_cast<float>(cube.levels.size() - 1), glm::reflect(-v, kUp)).x;
  std::printf("slot: truth %.3f, split sum %.3f", static_cast<double>(truth), static_cast<double>(split_sum));
  for (int samples : {4, 8, 16}) {
    const float got = gi::probe_lobe_radiance(cube, m, kCentre, kUp, v, samples, kCentre, kFarMin, kFarMax, true).x;
    std::printf(", %d samples %.3f", samples, static_cast<double>(got));
    if (samples >= 8) {
      EXPECT_LT(std::abs(got - truth), 0.5f * std::abs(split_sum - truth)) << samples << " samples";
    }
  }
  std::printf("\n");
  EXPECT_GT(split_sum - truth, 0.2f);  // the split sum's blur: the slot's bright sides
}

// Half a level finer (kProbeLobeLevelBias): the slot of the test above, seen at cos(theta_v) 0.15
// and 0.4, roughness 0.1 to 0.3, 4 to 16 samples. A sample read at its lobe's level takes in the
// level's texel-wide bilinear blur and the trilinear blend's wider tails, and reads the slot's bright
// sides; half a level finer errs less at every view, roughness and sample count.
TEST(ProbeLobe, HalfALevelFinerReadsTheSlotNearerItsTruth) {
  const gi::ProbeCube cube = slot_cube(32);
  for (float cos_v : {0.15f, 0.4f})
    for (float roughness : {0.1f, 0.2f, 0.3f}) {
      const engine::GltfBrdf m = engine::gltf_brdf(glm::vec3(0.5f), 0.0f, roughness);
      const glm::vec3 v(-std::sqrt(1.0f - cos_v * cos_v), cos_v, 0.0f);  // reflection towards +x
      const float truth = lobe_truth(m, v, 200000);
      std::printf("cos %.2f roughness %.1f: truth %.3f", static_cast<double>(cos_v), static_cast<double>(roughness),
                  static_cast<double>(truth));
      for (int samples : {4, 8, 16}) {
        const auto lookup = [&](float bias) {
          return gi::probe_lobe_radiance(cube, m, kCentre, kUp, v, samples, kCentre, kFarMin, kFarMax, true, nullptr,
                                         gi::kProbeBoxSideTolerance, gi::kProbeRimNearest, gi::kProbeOpeningLevelBias,
                                         bias)
              .x;
        };
        const float before = lookup(0.0f), finer = lookup(gi::kProbeLobeLevelBias);
        std::printf(", %d samples %.3f -> %.3f", samples, static_cast<double>(before), static_cast<double>(finer));
        EXPECT_LT(std::abs(finer - truth), std::abs(before - truth))
            << "cos " << cos_v << " roughness " << roughness << ", " << samples << " samples";
      }
      std::printf("\n");
    }
}

// The slot as an opening of the probe's box: a 32^2 probe at the centre of a 10 m box whose sides
// it saw everywhere but through the slot, where it saw 50 m (the demo corridor's far opening into
// the dark lamp room). The samples the lookup sends through the opening read a level finer
// (kProbeOpeningLevelBias), so less of the opening's bright frame blurs into them: at the
// runtime's 4 samples, cos(theta_v) 0.15 and roughness 0.1 and 0.2, the error against the lobe's
// truth at most 0.3x the lookup's without the bias (0.01x and 0.09x when written: 0.133 -> 0.000
// against 0.001, 0.259 -> 0.044 against 0.022); the same lobe where the probe saw the box's side
// everywhere is unchanged. (Every sample at its lobe's level otherwise: no kProbeLobeLevelBias.)
TEST(ProbeLobe, BeyondAnOpeningTheSamplesReadAFinerLevel) {
  const int size = 32;
  const glm::vec3 box_min(-5.0f), box_max(5.0f);
  gi::ProbeCube cube = slot_cube(size);
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 d = gi::cube_texel_direction(f, x, y, size);
        const glm::vec3 a = glm::abs(d);
        const float side = 5.0f / std::max({a.x, a.y, a.z});
        cube.distance[gi::cube_texel_index(f, x, y, size)] = slot_environment(d) == 0.0f ? 50.0f : side;
      }
  gi::ProbeCube closed = cube;  // the same light, every direction at the box's side
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 a = glm::abs(gi::cube_texel_direction(f, x, y, size));
        closed.distance[gi::cube_texel_index(f, x, y, size)] = 5.0f / std::max({a.x, a.y, a.z});
      }
  const float cos_v = 0.15f;
  const glm::vec3 v(-std::sqrt(1.0f - cos_v * cos_v), cos_v, 0.0f);  // reflection towards +x
  for (float roughness : {0.1f, 0.2f}) {
    const engine::GltfBrdf m = engine::gltf_brdf(glm::vec3(0.5f), 0.0f, roughness);
    const float truth = lobe_truth(m, v, 200000);
    const auto lookup = [&](const gi::ProbeCube& c, float bias) {
      return gi::probe_lobe_radiance(c, m, kCentre, kUp, v, gi::kProbeLobeSamples, kCentre, box_min, box_max, false,
                                     nullptr, gi::kProbeBoxSideTolerance, gi::kProbeRimNearest, bias, 0.0f)
          .x;
    };
    const float before = lookup(cube, 0.0f), finer = lookup(cube, gi::kProbeOpeningLevelBias);
    std::printf("roughness %.1f: truth %.3f, without the bias %.3f, with it %.3f\n", static_cast<double>(roughness),
                static_cast<double>(truth), static_cast<double>(before), static_cast<double>(finer));
    EXPECT_LT(std::abs(finer - truth), 0.3f * std::abs(before - truth)) << "roughness " << roughness;
    EXPECT_EQ(lookup(closed, 0.0f), lookup(closed, gi::kProbeOpeningLevelBias)) << "roughness " << roughness;
  }
}

// A constant cube (every level) of `value` whose distances are `distance(d)` per level-0 texel.
template <typename Distance>
gi::ProbeCube constant_cube(float value, const Distance& distance) {
  gi::ProbeCube cube = gi::make_probe_cube(16, gi::full_mip_count(16));
  for (auto& level : cube.levels) std::fill(level.begin(), level.end(), glm::vec3(value));
  cube.distance.resize(cube.levels[0].size());
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        cube.distance[gi::cube_texel_index(f, x, y, 16)] = distance(gi::cube_texel_direction(f, x, y, 16));
  return cube;
}

// Whether a probe saw the point (probe_visibility_weight): its captured distance towards the point
// at least 90% of the point's, less 5 cm; no distances: seen.
TEST(ProbeVisibility, AProbeSeesAPointNoFartherThanWhatItCapturedThere) {
  const gi::ProbeCube wall4 = constant_cube(1.0f, [](const glm::vec3&) { return 4.0f; });
  const glm::vec3 d = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  EXPECT_EQ(gi::probe_visibility_weight(wall4, kCentre, 4.0f * d), 1.0f);
  EXPECT_EQ(gi::probe_visibility_weight(wall4, kCentre, 4.4f * d), 1.0f);  // 4 >= 4.4 x 0.9 - 0.05
  EXPECT_EQ(gi::probe_visibility_weight(wall4, kCentre, 4.6f * d), gi::kProbeHiddenWeight);
  gi::ProbeCube none = wall4;
  none.distance.clear();
  EXPECT_EQ(gi::probe_visibility_weight(none, kCentre, 40.0f * d), 1.0f);
}

// Two probes sharing a 4 x 3 x 4 m box: A (radiance 1) at its centre, 1.5 m up, with a blocker
// 0.5 m in front of it towards +z; B (radiance 3) 0.8 m up behind the blocker, seeing everything.
// A floor point behind the blocker takes B's light (within A's 1e-3 share); one in front of it,
// seen by both, takes their mean, as every point does when the blend weighs by position alone.
TEST(ProbeVisibility, APointOneProbeDidNotSeeTakesTheOthersLight) {
  const glm::vec3 box_min(-2.0f, 0.0f, -2.0f), box_max(2.0f, 3.0f, 2.0f);
  const std::vector<gi::ProbeVolume> probes = {{{0.0f, 1.5f, 0.0f}, box_min, box_max},
                                               {{0.0f, 0.8f, 1.5f}, box_min, box_max}};
  const std::vector<gi::ProbeCube> cubes = {
      constant_cube(1.0f, [](const glm::vec3& d) { return d.z > 0.3f ? 0.5f : 10.0f; }),
      constant_cube(3.0f, [](const glm::vec3&) { return 10.0f; })};
  const engine::GltfBrdf brdf = engine::gltf_brdf(glm::vec3(0.5f), 0.0f, 0.1f);
  const glm::vec3 v = glm::normalize(glm::vec3(0.0f, 0.5f, -1.0f));
  const auto read = [&](const glm::vec3& p, bool visibility) {
    glm::vec3 out(-1.0f);
    EXPECT_TRUE(gi::blended_probe_lobe(probes, cubes, brdf, p, kUp, v, 4, out, visibility));
    return out.x;
  };
  const glm::vec3 behind(0.0f, 0.0f, 1.5f), in_front(0.0f, 0.0f, -1.5f);
  EXPECT_NEAR(read(behind, true), 3.0f, 0.01f);
  EXPECT_NEAR(read(in_front, true), 2.0f, 1e-4f);
  EXPECT_NEAR(read(behind, false), 2.0f, 1e-4f);
  glm::vec3 outside(0.0f);
  EXPECT_FALSE(gi::blended_probe_lobe(probes, cubes, brdf, {3.0f, 0.0f, 0.0f}, kUp, v, 4, outside));
}

}  // namespace
