// The light atlas's final gather (light_atlas/texel_gather.h) per texel against the path
// tracer at the same texel samples, edge texels included: a closed box against its closed
// form, a room with a box on the floor and a thin wall (concave and convex edges), a flat
// wall split into two charts (no jump at the chart border), determinism.
#include <gtest/gtest.h>

#include <cstdio>

#include <gi/error_metrics.h>

#include "analytic_support.h"
#include "light_atlas/light_atlas.h"
#include "raytrace/atlas_reference.h"
#include "raytrace/texel_samples.h"

namespace {

using analytic::kPi;

gi::LightAtlasSettings gather_settings(float density, int rays) {
  gi::LightAtlasSettings s;
  s.texels_per_metre = density;
  s.vpl_count = 100;
  s.bounces = 64;
  s.final_pass = gi::LightAtlasSettings::FinalPass::TexelGather;
  s.gather = {.direct_samples = 16, .solve_rays = 64, .gather_rays = rays, .bounces = 64};
  s.threads = 2;
  return s;
}

gi::ReferenceSettings reference(int spp) {
  gi::ReferenceSettings r;
  r.samples_per_pixel = spp;
  r.max_bounces = -1;
  r.seed = 99;
  r.threads = 2;
  return r;
}

gi::AtlasTexels visible_texels(const gi::BakeInput& input, const gi::AtlasLayout& layout) {
  return gi::sample_atlas_texels(input, layout, gi::TexelPlacement::VisibleSurface).value();
}

// A point light in a closed box: every texel, the ones on the twelve edges and the eight
// corners included (the VPL shooting reads half or a quarter of the light there, docs/
// light_atlas.md), against the path tracer at the same sample; the area mean against the
// closed form Phi rho / ((1 - rho) A).
TEST(TexelGather, ClosedBoxEdgeAndCornerTexelsMatchThePathTracer) {
  constexpr float kRho = 0.5f, kIntensity = 5.0f;
  gi::BakeInput input = analytic::closed_box(2.0f, analytic::lambert(kRho));
  input.lights.push_back(analytic::point_light({0.3f, -0.2f, 0.1f}, kIntensity));
  auto bake = gi::bake_light_atlas(input, gather_settings(6.0f, 256));
  ASSERT_TRUE(bake) << bake.error().to_string();
  const gi::AtlasTexels texels = visible_texels(input, bake->layout);
  auto truth = gi::reference_atlas_irradiance(input, texels, reference(4096));
  ASSERT_TRUE(truth) << truth.error().to_string();
  analytic::ErrorStats interior, edge;
  double sum = 0.0;
  std::size_t n = 0;
  const float texel = 1.0f / bake->layout.texels_per_metre;
  for (std::size_t t = 0; t < texels.valid.size(); ++t) {
    if (!texels.valid[t]) continue;
    const bool near_edge = analytic::box_edge_distance(texels.position[t], 1.0f) < texel;
    (near_edge ? edge : interior)
        .add(static_cast<double>(bake->irradiance[t].y), static_cast<double>(truth->indirect[t].y), t);
    sum += static_cast<double>(bake->irradiance[t].y), ++n;
  }
  const double expected = 4.0 * kPi * double{kIntensity} * double{kRho} / ((1.0 - double{kRho}) * 24.0);
  std::printf(
      "closed box, gather 64 kept + 256 rays vs path tracer (4096 spp) per texel; texel mean / closed form %.4f\n",
      sum / static_cast<double>(n) / expected);
  interior.print("interior texels");
  edge.print("texels within one texel of an edge");
  EXPECT_GT(edge.n, 100u);
  // Measured: interior rms 0.011 (max 0.036), edge rms 0.013 (max 0.044), bias -0.3%.
  EXPECT_LT(interior.max_rel, 0.06);
  EXPECT_LT(interior.rms(), 0.02);
  EXPECT_LT(edge.max_rel, 0.08);
  EXPECT_LT(edge.rms(), 0.03);
  EXPECT_LT(std::fabs(edge.bias()), 0.02);
  // Texels are not equal-area (edge texels stand for less), so the texel mean is near, not at, the area mean.
  EXPECT_NEAR(sum / static_cast<double>(n) / expected, 1.0, 0.05);
}

// A 3 m room with a 0.6 m box on its floor and a free-standing wall 2 cm thick: concave
// edges (floor against wall, floor against box), convex ones (the box's top, the thin
// wall's rim), a floor that runs under both. Texels within one texel of any of them against
// the path tracer.
gi::BakeInput room_with_box_and_thin_wall() {
  gi::BakeInput in = analytic::closed_box(3.0f, analytic::lambert(0.6f));
  gi::BakePrimitive box, wall;
  const float f = -1.5f;  // floor height
  // Box [-0.9, -0.3] x [f, f + 0.6] x [-0.3, 0.3], outward faces, no bottom.
  const glm::vec3 lo(-0.9f, f, -0.3f);
  const float s = 0.6f;
  analytic::add_quad(box, lo + glm::vec3(0, s, 0), {0, 0, s}, {s, 0, 0});  // top, +y
  analytic::add_quad(box, lo, {0, s, 0}, {0, 0, s});                       // x-, faces -x
  analytic::add_quad(box, lo + glm::vec3(s, 0, 0), {0, 0, s}, {0, s, 0});  // x+, +x
  analytic::add_quad(box, lo, {s, 0, 0}, {0, s, 0});                       // z-, -z
  analytic::add_quad(box, lo + glm::vec3(0, 0, s), {0, s, 0}, {s, 0, 0});  // z+, +z
  analytic::add_static(in, std::move(box), analytic::lambert(0.7f), "box");
  // Thin wall: x in [0.6, 0.62], z in [-1.0, 1.0], height 1.4, closed on top.
  const float x0 = 0.6f, x1 = 0.62f, h = 1.4f;
  analytic::add_quad(wall, {x0, f, -1.0f}, {0, 0, 2.0f}, {0, h, 0});            // faces -x
  analytic::add_quad(wall, {x1, f, -1.0f}, {0, h, 0}, {0, 0, 2.0f});            // faces +x
  analytic::add_quad(wall, {x0, f + h, -1.0f}, {0, 0, 2.0f}, {x1 - x0, 0, 0});  // top, +y
  analytic::add_quad(wall, {x0, f, -1.0f}, {x1 - x0, 0, 0}, {0, h, 0});         // end z-, -z
  analytic::add_quad(wall, {x0, f, 1.0f}, {0, h, 0}, {x1 - x0, 0, 0});          // end z+, +z
  analytic::add_static(in, std::move(wall), analytic::lambert(0.5f), "thin wall");
  in.lights.push_back(analytic::point_light({-0.2f, 0.8f, 0.4f}, 20.0f));
  return in;
}

// The sweeps' error against the truth (error_metrics.h: the reference's own sampling
// variance removed) must not depend on how noisy the reference is: one bake against
// references of 1024 and 8192 samples per texel (noise 2.5x and 0.9x the bake's error).
TEST(TexelGather, ErrorAgainstTheTruthDoesNotDependOnTheReferencesSamples) {
  gi::BakeInput input = analytic::closed_box(2.0f, analytic::lambert(0.6f));
  input.lights.push_back(analytic::point_light({-0.4f, 0.5f, 0.2f}, 5.0f));
  auto bake = gi::bake_light_atlas(input, gather_settings(6.0f, 64));
  ASSERT_TRUE(bake) << bake.error().to_string();
  const gi::AtlasTexels texels = visible_texels(input, bake->layout);
  const gi::RgbField baked = gi::RgbField::from_texels(texels.width, texels.height, bake->irradiance, texels.valid);
  double truth_error[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k) {
    const int spp = k == 0 ? 1024 : 8192;
    auto truth = gi::reference_atlas_irradiance(input, texels, reference(spp));
    ASSERT_TRUE(truth) << truth.error().to_string();
    const gi::RgbField ref =
        gi::RgbField::from_texels(texels.width, texels.height, truth->indirect, texels.valid, truth->indirect_variance);
    const gi::ErrorReport e = gi::compare_rgb(baked, ref);
    ASSERT_TRUE(e.ok()) << e.problem;
    std::printf("reference %4d spp: its noise %.4f, rel RMSE vs it %.4f, vs the truth %.4f\n", spp, e.reference_noise,
                e.rel_rmse, e.truth_rel_rmse);
    truth_error[k] = e.truth_rel_rmse;
  }
  EXPECT_GT(truth_error[1], 0.0);
  // Measured 0.0138 and 0.0118 (ratio 1.17; without the variance removed: 0.0327 and 0.0158).
  EXPECT_NEAR(truth_error[0] / truth_error[1], 1.0, 0.25);
}

TEST(TexelGather, ConcaveAndConvexEdgesOfABoxAndAThinWallMatchThePathTracer) {
  const gi::BakeInput input = room_with_box_and_thin_wall();
  auto bake = gi::bake_light_atlas(input, gather_settings(6.0f, 256));
  ASSERT_TRUE(bake) << bake.error().to_string();
  const gi::AtlasTexels texels = visible_texels(input, bake->layout);
  auto truth = gi::reference_atlas_irradiance(input, texels, reference(4096));
  ASSERT_TRUE(truth) << truth.error().to_string();
  const float texel = 1.0f / bake->layout.texels_per_metre;
  // Distance to the nearest edge of the box, the wall or the room (axis-aligned features).
  const auto near_feature = [&](glm::vec3 p) {
    const float planes_x[] = {-1.5f, 1.5f, -0.9f, -0.3f, 0.6f, 0.62f};
    const float planes_y[] = {-1.5f, 1.5f, -0.9f, -0.1f};
    const float planes_z[] = {-1.5f, 1.5f, -0.3f, 0.3f, -1.0f, 1.0f};
    int close = 0;
    for (float x : planes_x) close += std::fabs(p.x - x) < texel;
    for (float y : planes_y) close += std::fabs(p.y - y) < texel;
    for (float z : planes_z) close += std::fabs(p.z - z) < texel;
    return close >= 2;  // on one plane and within a texel of another: an edge
  };
  analytic::ErrorStats flat, edge;
  for (std::size_t t = 0; t < texels.valid.size(); ++t) {
    if (!texels.valid[t]) continue;
    const double ref = static_cast<double>(truth->indirect[t].y);
    if (!(ref > 0.02)) continue;  // texels hidden under the box or the wall (no light reaches them)
    (near_feature(texels.position[t]) ? edge : flat).add(static_cast<double>(bake->irradiance[t].y), ref, t);
  }
  std::printf("room with a box and a 2 cm wall, gather vs path tracer (4096 spp) per texel\n");
  flat.print("texels away from edges");
  edge.print("texels within one texel of an edge");
  // Measured at 8 texels/m: flat rms 0.019; edges rms 0.026, bias -0.007, worst 0.22 (a dim
  // texel where the reference's own noise is a few percent).
  EXPECT_GT(edge.n, 300u);
  EXPECT_LT(flat.rms(), 0.03);
  EXPECT_LT(edge.rms(), 0.04);
  EXPECT_LT(edge.max_rel, 0.30);
  EXPECT_LT(std::fabs(edge.bias()), 0.02);  // no dark (or bright) row along the edges
}

// One flat wall made of two meshes side by side (two charts): texel pairs on either side of
// the seam differ as the path tracer's do, not by a chart boundary's step.
TEST(TexelGather, FlatWallSplitIntoTwoChartsHasNoJumpAtTheSeam) {
  gi::BakeInput input = analytic::closed_box(2.0f, analytic::lambert(0.5f));
  // The box's x = +1 wall, replaced by two halves 1 mm in front of it (z < 0 and z > 0).
  gi::BakePrimitive a, b;
  analytic::add_quad(a, {0.999f, -1.0f, -1.0f}, {0, 0, 1.0f}, {0, 2.0f, 0});
  analytic::add_quad(b, {0.999f, -1.0f, 0.0f}, {0, 0, 1.0f}, {0, 2.0f, 0});
  analytic::add_static(input, std::move(a), analytic::lambert(0.5f), "wall half z-");
  analytic::add_static(input, std::move(b), analytic::lambert(0.5f), "wall half z+");
  input.lights.push_back(analytic::point_light({-0.4f, 0.5f, 0.1f}, 5.0f));
  auto bake = gi::bake_light_atlas(input, gather_settings(8.0f, 256));
  ASSERT_TRUE(bake) << bake.error().to_string();
  const gi::AtlasTexels texels = visible_texels(input, bake->layout);
  auto truth = gi::reference_atlas_irradiance(input, texels, reference(8192));
  ASSERT_TRUE(truth) << truth.error().to_string();
  // Texels of the two halves nearest to the seam, paired by height.
  const float texel = 1.0f / bake->layout.texels_per_metre;
  const int half_a = static_cast<int>(bake->layout.meshes.size()) - 2;
  std::vector<std::size_t> left, right;
  for (std::size_t t = 0; t < texels.valid.size(); ++t) {
    if (!texels.valid[t] || std::fabs(texels.position[t].z) > texel) continue;
    if (texels.mesh[t] == half_a) left.push_back(t);
    if (texels.mesh[t] == half_a + 1) right.push_back(t);
  }
  ASSERT_GT(left.size(), 10u);
  ASSERT_GT(right.size(), 10u);
  double worst = 0.0, sum_sq = 0.0;
  std::size_t pairs = 0;
  for (std::size_t l : left) {
    std::size_t best = right.front();
    for (std::size_t r : right)
      if (std::fabs(texels.position[r].y - texels.position[l].y) <
          std::fabs(texels.position[best].y - texels.position[l].y))
        best = r;
    if (std::fabs(texels.position[best].y - texels.position[l].y) > 0.5f * texel) continue;
    const double baked_jump = static_cast<double>(bake->irradiance[best].y - bake->irradiance[l].y);
    const double true_jump = static_cast<double>(truth->indirect[best].y - truth->indirect[l].y);
    const double scale = 0.5 * static_cast<double>(truth->indirect[best].y + truth->indirect[l].y);
    const double err = (baked_jump - true_jump) / scale;
    worst = std::max(worst, std::fabs(err));
    sum_sq += err * err;
    ++pairs;
  }
  const double rms = std::sqrt(sum_sq / static_cast<double>(pairs));
  std::printf("two-chart wall: %zu pairs across the seam, jump error (relative to the level) rms %.4f max %.4f\n",
              pairs, rms, worst);
  ASSERT_GT(pairs, 10u);
  // Measured (12 texels/m): rms 0.016, max 0.044; part of it is the reference's noise.
  EXPECT_LT(rms, 0.03);
  EXPECT_LT(worst, 0.05);
}

TEST(TexelGather, BitIdenticalForAnyThreadCount) {
  const gi::BakeInput input = room_with_box_and_thin_wall();
  gi::LightAtlasSettings s = gather_settings(4.0f, 32);
  s.gather.filter_radius_texels = 1.5f;
  s.threads = 1;
  auto one = gi::bake_light_atlas(input, s);
  s.threads = 4;
  auto four = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(one && four);
  EXPECT_TRUE(one->irradiance == four->irradiance);
  EXPECT_GT(one->stats.gather_iterations, 3);
}

gi::BakeInput room_lit_through_a_skylight();  // below

TEST(TexelGather, EmitterRaysAreBitIdenticalForAnyThreadCount) {
  const gi::BakeInput input = room_lit_through_a_skylight();
  gi::LightAtlasSettings s = gather_settings(3.0f, 16);
  s.gather.solve_rays = 16;
  s.gather.emitter_rays = 16;
  s.gather.filter_radius_texels = 1.5f;
  s.threads = 1;
  auto one = gi::bake_light_atlas(input, s);
  s.threads = 3;
  auto three = gi::bake_light_atlas(input, s);
  s.gather.emitter_rays = 0;
  auto cosine = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(one && three && cosine);
  EXPECT_TRUE(one->irradiance == three->irradiance);
  EXPECT_FALSE(one->irradiance == cosine->irradiance);  // the emitter rays did run
}

TEST(TexelGather, RejectsBadSettingsAndCancels) {
  const gi::BakeInput input = room_with_box_and_thin_wall();
  gi::LightAtlasSettings s = gather_settings(4.0f, 32);
  s.gather.solve_rays = 0;
  auto bad = gi::bake_light_atlas(input, s);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("solve_rays"), std::string::npos) << bad.error().message;
  s = gather_settings(4.0f, 32);
  s.progress = [](double f) { return f < 0.5; };
  auto cancelled = gi::bake_light_atlas(input, s);
  ASSERT_FALSE(cancelled);
  EXPECT_NE(cancelled.error().message.find("cancel"), std::string::npos) << cancelled.error().message;
}

// Issue 35's structure in a small scene: a 6 x 3 x 6 m room closed but for a 0.8 m hole in
// its ceiling, through which a sun lights a patch of 0.64 m^2 of the floor; the rest of the
// room gets that patch's light by bounces (Sponza's arcades off its courtyard floor). The
// sky is black.
gi::BakeInput room_lit_through_a_skylight() {
  const gi::BakeMaterial wall = analytic::lambert(0.6f);
  gi::BakePrimitive p;
  const float w = 6.0f, h = 3.0f, lo = -3.0f;
  analytic::add_quad(p, {lo, 0, lo}, {0, 0, w}, {w, 0, 0});   // floor, +y
  analytic::add_quad(p, {lo, 0, lo}, {w, 0, 0}, {0, h, 0});   // z = -3, +z
  analytic::add_quad(p, {lo, 0, -lo}, {0, h, 0}, {w, 0, 0});  // z = +3, -z
  analytic::add_quad(p, {lo, 0, lo}, {0, h, 0}, {0, 0, w});   // x = -3, +x
  analytic::add_quad(p, {-lo, 0, lo}, {0, 0, w}, {0, h, 0});  // x = +3, -x
  // Ceiling (faces -y) around the hole x, z in [1.8, 2.6].
  const float a = 1.8f, b = 2.6f;
  analytic::add_quad(p, {lo, h, lo}, {w, 0, 0}, {0, 0, a - lo});     // z < 1.8
  analytic::add_quad(p, {lo, h, b}, {w, 0, 0}, {0, 0, -lo - b});     // z > 2.6
  analytic::add_quad(p, {lo, h, a}, {a - lo, 0, 0}, {0, 0, b - a});  // x < 1.8 beside the hole
  analytic::add_quad(p, {b, h, a}, {-lo - b, 0, 0}, {0, 0, b - a});  // x > 2.6 beside the hole
  gi::BakeInput in;
  in.name = "room lit through a skylight";
  analytic::add_static(in, std::move(p), wall, "room");
  gi::BakeLight sun;
  sun.name = "sun";
  sun.light.type = engine::LightType::Directional;
  sun.light.intensity = 700.0f;
  // Light travels along the node's -Z: down through the hole, a little slanted.
  sun.light_to_world =
      glm::mat4_cast(glm::quatLookAt(glm::normalize(glm::vec3(-0.1f, -1.0f, -0.05f)), glm::vec3(0.0f, 0.0f, 1.0f)));
  in.lights.push_back(sun);
  return in;
}

// The emitter-sampled gather (texel_emitters.h) against the cosine gather at equal fresh
// rays, per texel: against the path tracer (its noise removed) and against the gather's own
// converged value (the same kept-ray solve read by 4096 cosine rays, so the same discretization of the
// sunlit patch, without the path tracer's noise): lower error at the 95th percentile and
// overall, and the same mean (unbiased).
TEST(TexelGather, EmitterSamplingFindsASmallSunlitPatchThatLightsTheRoom) {
  const gi::BakeInput input = room_lit_through_a_skylight();
  // The same kept-ray solve (32 rays) as the runs below, read by 4096 fresh cosine rays.
  gi::LightAtlasSettings s = gather_settings(6.0f, 4096);
  s.gather.solve_rays = 32;
  auto converged = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(converged) << converged.error().to_string();
  const gi::AtlasTexels texels = visible_texels(input, converged->layout);
  auto truth = gi::reference_atlas_irradiance(input, texels, reference(1024));
  ASSERT_TRUE(truth) << truth.error().to_string();
  const gi::RgbField ref =
      gi::RgbField::from_texels(texels.width, texels.height, truth->indirect, texels.valid, truth->indirect_variance);
  struct Score {
    double truth_error, p95, rms, mean_ratio;
  };
  const auto score = [&](const gi::LightAtlasBake& bake, const char* what) {
    std::vector<double> rel;
    double sum = 0.0, sum_ref = 0.0, sq = 0.0;
    for (std::size_t t = 0; t < texels.valid.size(); ++t) {
      if (!texels.valid[t]) continue;
      const double r = static_cast<double>(converged->irradiance[t].y), x = static_cast<double>(bake.irradiance[t].y);
      rel.push_back(std::fabs(x - r) / r);
      sq += rel.back() * rel.back();
      sum += x, sum_ref += r;
    }
    std::sort(rel.begin(), rel.end());
    const gi::ErrorReport e =
        gi::compare_rgb(gi::RgbField::from_texels(texels.width, texels.height, bake.irradiance, texels.valid), ref);
    const Score out{e.truth_rel_rmse, rel[rel.size() * 95 / 100], std::sqrt(sq / static_cast<double>(rel.size())),
                    sum / sum_ref};
    std::printf("  %-34s vs truth %.4f | vs converged: 95th pct %.4f rms %.4f mean ratio %.4f | rays %llu\n", what,
                out.truth_error, out.p95, out.rms, out.mean_ratio, static_cast<unsigned long long>(bake.stats.rays));
    return out;
  };
  std::printf("room lit through a skylight, 32 kept rays + fresh rays, vs path tracer (1024 spp, noise %.4f)\n",
              gi::compare_rgb(ref, ref).reference_noise);
  score(*converged, "converged: 32 kept + 4096 cosine");
  s.gather.gather_rays = 128;
  auto cosine = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(cosine);
  const Score c = score(*cosine, "128 cosine rays");
  s.gather.gather_rays = 64;
  s.gather.emitter_rays = 64;
  auto emitter = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(emitter);
  const Score m = score(*emitter, "64 cosine + 64 emitter rays (MIS)");
  s.gather.gather_rays = 1024;
  s.gather.emitter_rays = 1024;
  auto many = gi::bake_light_atlas(input, s);
  ASSERT_TRUE(many);
  const Score mm = score(*many, "1024 cosine + 1024 emitter rays");
  // Measured against the converged gather: 95th percentile 0.70 -> 0.32, rms 0.34 -> 0.21,
  // mean ratio 0.988 and 0.999 (1024 + 1024 rays: 1.0006); against the path tracer (noise
  // removed) 0.232 -> 0.204, the converged gather's own 0.068. Until the reads across a
  // shadow edge took the lights' direct light at the landing point (issue 35, third pass)
  // the gains were larger (rms 0.31 -> 0.094, truth 0.235 -> 0.152) but the converged gather
  // itself was 0.135 off: the cosine rays' blurred read of the patch's edges then cost more.
  EXPECT_LT(m.p95, 0.5 * c.p95);
  EXPECT_LT(m.rms, 0.7 * c.rms);
  EXPECT_LT(m.truth_error, 0.95 * c.truth_error);
  EXPECT_NEAR(m.mean_ratio, 1.0, 0.01);
  EXPECT_NEAR(mm.mean_ratio, 1.0, 0.01);
}

}  // namespace
