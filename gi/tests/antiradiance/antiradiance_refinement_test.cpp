// Issue 37's refinement: adaptive leaves (fine near the deforming instances, coarse far from
// them) and leaf-leaf links split virtually until their pieces meet the oracle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include <glm/gtc/constants.hpp>

#include "antiradiance/antiradiance_region.h"
#include "antiradiance/directional_bins.h"
#include "antiradiance/element_hierarchy.h"
#include "antiradiance/link_mesh.h"
#include "antiradiance_scenes.h"

namespace {

// The door scene's swept sphere: the hinge (1, 0, -0.5) through the farthest door corner
// (0.04, +-0.5, 1) in the hinge frame.
const glm::vec3 kHinge(1.0f, 0.0f, -0.5f);
const float kReach = std::sqrt(0.04f * 0.04f + 0.25f + 1.0f);

float distance_to_sweep(const gi::ElementNode& n) { return glm::length(n.center - kHinge) - n.radius_m - kReach; }

gi::AntiradianceSettings adaptive() {
  gi::AntiradianceSettings s;
  s.patch_size_m = 0.5f;
  s.near_patch_size_m = 0.1f;
  s.near_radius_m = 0.3f;
  s.bins_per_side = 6;
  return s;
}

TEST(AntiradianceAdaptiveLeaves, AreFineOnTheDoorAndNearItsSweep) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  auto h = gi::build_element_hierarchy(scene.input, adaptive());
  ASSERT_TRUE(h) << h.error().to_string();
  std::size_t door = 0, near = 0;
  for (std::int32_t l : h->leaves) {
    const gi::ElementNode& n = h->nodes[static_cast<std::size_t>(l)];
    // A piece's bounding radius (centroid to its farthest corner) is below its longest edge.
    if (n.group == 1) {
      EXPECT_LT(n.radius_m, 0.1f) << "door leaf " << l;
      ++door;
    } else if (distance_to_sweep(n) <= 0.3f) {
      EXPECT_LT(n.radius_m, 0.1f) << "static leaf " << l << " within the near radius";
      ++near;
    }
  }
  // The door's six faces (1 x 1 m, 0.04 m thick) at <= 0.1 m pieces: hundreds of leaves.
  EXPECT_GT(door, 400u);
  EXPECT_GT(near, 100u);
}

TEST(AntiradianceAdaptiveLeaves, AreUnchangedFarFromTheSweep) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  gi::AntiradianceSettings uniform = adaptive();
  uniform.near_patch_size_m = 0.0f;
  auto fine = gi::build_element_hierarchy(scene.input, adaptive());
  auto coarse = gi::build_element_hierarchy(scene.input, uniform);
  ASSERT_TRUE(fine && coarse);
  EXPECT_GT(fine->leaf_count(), 2 * coarse->leaf_count());
  // A uniform leaf whose every ancestor piece (up to its source triangle) is far from the sweep
  // is split the same way in the adaptive build: the same leaf is there.
  std::map<std::pair<float, float>, int> fine_leaves;  // (centre x + 3 y + 7 z, area) -> count
  const auto key = [](const gi::ElementNode& n) {
    return std::make_pair(n.center.x + 3.0f * n.center.y + 7.0f * n.center.z, n.area_m2);
  };
  for (std::int32_t l : fine->leaves) ++fine_leaves[key(fine->nodes[static_cast<std::size_t>(l)])];
  std::size_t far = 0;
  for (std::int32_t l : coarse->leaves) {
    bool all_far = true;
    for (std::int32_t i = l; i >= 0 && coarse->nodes[static_cast<std::size_t>(i)].normal != glm::vec3(0.0f);
         i = coarse->nodes[static_cast<std::size_t>(i)].parent)
      all_far = all_far && distance_to_sweep(coarse->nodes[static_cast<std::size_t>(i)]) > 0.3f;
    if (!all_far || coarse->nodes[static_cast<std::size_t>(l)].group != 0) continue;
    ++far;
    EXPECT_GT(fine_leaves[key(coarse->nodes[static_cast<std::size_t>(l)])], 0) << "far leaf " << l << " was split";
  }
  EXPECT_GT(far, 20u);
}

TEST(AntiradianceAdaptiveLeaves, RejectsANegativeNearSize) {
  const artest::DoorScene scene = artest::door_scene(0.0f);
  gi::AntiradianceSettings s = adaptive();
  s.near_patch_size_m = -0.1f;
  auto h = gi::build_element_hierarchy(scene.input, s);
  ASSERT_FALSE(h);
  EXPECT_NE(h.error().message.find("near_patch_size_m"), std::string::npos);
}

// Every linked pair meets the oracle, or is a pair of leaves whose virtual pieces meet it at
// the pair's distance (pi (r^2 / n) / d^2 <= threshold); a pair can only run into the piece
// cap (64 here) when its two spheres overlap (touching leaves: a door's edge against its face).
TEST(AntiradianceLinkOracle, IsMetByEveryLinkOnceLeafLinksAreSplit) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  gi::AntiradianceSettings s = adaptive();
  s.leaf_link_pieces = 64;
  auto h = gi::build_element_hierarchy(scene.input, s);
  ASSERT_TRUE(h);
  const gi::DirectionalBins bins(s.bins_per_side);
  const gi::LinkMesh mesh = gi::link_elements(*h, bins, s);
  const float threshold = gi::oracle_threshold_sr(bins, s);
  std::size_t split = 0, met = 0, capped = 0;
  for (const gi::Link& l : mesh.links) {
    const gi::ElementNode& r = h->nodes[static_cast<std::size_t>(l.receiver)];
    const gi::ElementNode& e = h->nodes[static_cast<std::size_t>(l.sender)];
    if (gi::meets_oracle(r, e, threshold)) {
      ++met;
      continue;
    }
    ASSERT_TRUE(r.child_count == 0 && e.child_count == 0) << "a pair of inner elements linked against the oracle";
    const gi::LinkPieces p = gi::link_pieces(r, e, threshold, s.leaf_link_pieces);
    const float d2 = glm::dot(r.center - e.center, r.center - e.center);
    const auto piece_ok = [&](const gi::ElementNode& n, int pieces) {
      return glm::pi<float>() * n.radius_m * n.radius_m / (static_cast<float>(pieces) * d2) <= threshold * 1.0001f;
    };
    if (piece_ok(r, p.receiver) && piece_ok(e, p.sender)) {
      ++split;
    } else {
      ++capped;
      EXPECT_LT(std::sqrt(d2), r.radius_m + e.radius_m)
          << "capped without touching: " << l.receiver << " <- " << l.sender;
    }
  }
  EXPECT_GT(met, 0u);
  EXPECT_GT(split, 0u);   // the scene has near pairs of leaves that fail the oracle
  EXPECT_GT(capped, 0u);  // and touching ones (the door's edges against its faces)
}

// Two parallel facing 0.5 x 0.5 m plates 0.3 m apart, one leaf each (1 m patches): with a
// sender of intensity 1 W/sr spread evenly over its area, the receiver's mean irradiance is
// (1 / A_s) * mean over the receiver of the integral of cos_r / d^2 over the sender. The link
// sums F_b omega_b cos_b over its bins. Measured: truth 5.37 /m^2; unsplit (the triangles'
// centres, regularized as touching leaves) 4.31, 20% below; split (256 pieces) 5.68, 5.8%
// above (disc pieces standing for the triangles, bin directions for the piece directions).
TEST(AntiradianceLinkOracle, SplitLeafLinkMatchesTheNearFieldIrradiance) {
  gi::BakeInput in;
  gi::BakePrimitive a, b;
  artest::add_quad(a, {0, -0.25f, -0.25f}, {0, 0.5f, 0}, {0, 0, 0.5f});     // x = 0, facing +x
  artest::add_quad(b, {0.3f, -0.25f, -0.25f}, {0, 0, 0.5f}, {0, 0.5f, 0});  // x = 0.3, facing -x
  artest::add_mesh(in, "a", a, glm::vec3(0.5f), false);
  artest::add_mesh(in, "b", b, glm::vec3(0.5f), true);
  // The exact value: 64 x 64 midpoints on each plate.
  const int g = 64;
  double exact = 0.0;
  for (int i = 0; i < g * g; ++i)
    for (int j = 0; j < g * g; ++j) {
      const glm::dvec2 pr((i % g + 0.5) / g * 0.5, (i / g + 0.5) / g * 0.5);
      const glm::dvec2 ps((j % g + 0.5) / g * 0.5, (j / g + 0.5) / g * 0.5);
      const double dy = pr.x - ps.x, dz = pr.y - ps.y, d2 = 0.09 + dy * dy + dz * dz;
      exact += (0.3 / std::sqrt(d2)) / d2;  // cos_r / d^2
    }
  exact /= static_cast<double>(g * g) * static_cast<double>(g * g);  // mean over both: (1 / A_s) integral

  const auto link_irradiance = [&](int pieces) {
    gi::AntiradianceSettings s;
    s.patch_size_m = 1.0f;
    s.bins_per_side = 8;
    s.leaf_link_pieces = pieces;
    auto h = gi::build_element_hierarchy(in, s);
    EXPECT_TRUE(h);
    const gi::DirectionalBins bins(s.bins_per_side);
    const gi::LinkMesh mesh = gi::link_elements(*h, bins, s);
    double e = 0.0;
    for (const gi::Link& l : mesh.links) {
      const gi::ElementNode& r = h->nodes[static_cast<std::size_t>(l.receiver)];
      const gi::ElementNode& src = h->nodes[static_cast<std::size_t>(l.sender)];
      if (r.child_count != 0 || src.child_count != 0 || r.group != 1 || src.group != 0) continue;
      // The receiver is the two triangles of plate b; the sender the two of plate a: half
      // the sender's intensity each, the receiver's mean over its two triangles.
      const double cos_b = std::max(0.0f, -glm::dot(r.normal, bins.direction(l.bin)));
      e += 0.5 * 0.5 * cos_b * static_cast<double>(l.form_factor * bins.solid_angle(l.bin));
    }
    return e;
  };
  const double unsplit = link_irradiance(0), split = link_irradiance(256);
  EXPECT_GT(std::abs(unsplit / exact - 1.0), 0.15) << "unsplit " << unsplit << " exact " << exact;
  EXPECT_NEAR(split / exact, 1.0, 0.08) << "split " << split << " exact " << exact;
}

}  // namespace

namespace {

// Receiver mean indirect irradiance (W/m^2, red) of the door scene solved with `s`.
float receiver_light(float door_deg, const gi::AntiradianceSettings& s) {
  const artest::DoorScene scene = artest::door_scene(door_deg);
  auto region = gi::AntiradianceRegion::create(scene.input, s);
  EXPECT_TRUE(region);
  if (!region) return 0.0f;
  region->update();
  return artest::instance_mean(region->hierarchy(), scene.input, scene.receiver, region->irradiance()).x;
}

// The closed door's leak (docs/antiradiance.md: 6.8% of the open light at 64 bins, 0.25 m
// leaves, links regardless) with the leaf-leaf links split, at 64 and 144 bins. Measured:
// 6.3% and -0.8% (144 bins cancel slightly more than the open light). Bound: 8%.
TEST(AntiradianceLinkOracle, SplitLeafLinksKeepTheClosedDoorLeakBounded) {
  for (int n : {8, 12}) {
    gi::AntiradianceSettings s;
    s.patch_size_m = 0.25f;
    s.bins_per_side = n;
    s.leaf_link_pieces = 64;
    const float open = receiver_light(90.0f, s), closed = receiver_light(0.0f, s);
    std::printf("bins %d split: open %.5f closed %.5f (leak %.2f%%)\n", n * n, double(open), double(closed),
                100.0 * double(closed / open));
    ASSERT_GT(open, 0.01f);
    EXPECT_LE(std::abs(closed), 0.08f * open);
  }
}

}  // namespace
