// The PRM pane sum on the GPU (llvmpipe through EGL; fails, never skips, without a context)
// against a CPU reference of the same formula (prm_runtime.h): atlas(texels[i]) = base +
// sum_k weight_k x pane_k[i]. Panes travel as half floats, so the GPU sum must lie within
// kRelativeTolerance x sum_k |weight_k| |pane_k[i]| (per channel) + kAbsoluteTolerance of the
// reference: half rounding is at most 2^-11 (~4.9e-4) of each pane value, float
// accumulation adds ~1e-7 per term.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <gi/bake_input.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "core/random.h"
#include "gl_context.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
#include "prm/prm_runtime.h"
#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace {

constexpr double kRelativeTolerance = 1e-3;
constexpr double kAbsoluteTolerance = 1e-6;

using gltest::headless_or_fail;

// A hand-made PRM: a pseudo-random ascending two-thirds of the atlas texels, pane values
// log-uniform in [min_value, max_value] per channel.
gi::Prm synthetic_prm(int width, int height, int clusters, float min_value = 1e-3f, float max_value = 1e2f,
                      std::uint64_t seed = 7) {
  gi::Prm prm;
  prm.width = width;
  prm.height = height;
  prm.cluster_count = clusters;
  const auto atlas = static_cast<std::uint32_t>(width * height);
  for (std::uint32_t t = 0; t < atlas; ++t)
    if (gi::Pcg32::for_item(seed, t).next_u32() % 3 != 0) prm.texels.push_back(t);
  const float decades = std::log10(max_value / min_value);
  std::vector<float> dense(static_cast<std::size_t>(clusters) * prm.texels.size() * 3);
  for (std::size_t f = 0; f < dense.size(); ++f) {
    gi::Pcg32 rng = gi::Pcg32::for_item(seed + 1, f);
    dense[f] = min_value * std::pow(10.0f, decades * rng.next_float());
  }
  prm.cluster_size.assign(static_cast<std::size_t>(clusters), 1);
  gi::set_dense_panes(prm, dense);
  return prm;
}

// Chunks (blocks of eight slots) of one dense pane on the GPU: every 8 x 8 tile padded.
std::size_t dense_pane_chunks(const gi::Prm& prm) {
  std::size_t chunks = 0;
  for (std::size_t k = 0; k < prm.panes.tiles.tiles(); ++k) chunks += (prm.panes.tiles.size(k) + 7) / 8;
  return chunks;
}

// K clusters with distinct RGB weights in [0.05, 2], cluster ids spread over all clusters.
std::vector<gi::ClusterWeight> pick(int clusters, int k, std::uint64_t seed) {
  std::vector<gi::ClusterWeight> w;
  for (int i = 0; i < k; ++i) {
    gi::Pcg32 rng = gi::Pcg32::for_item(seed, static_cast<std::uint64_t>(i));
    const auto cluster = static_cast<std::uint32_t>((i * 7 + static_cast<int>(seed)) % clusters);
    w.push_back({cluster, glm::vec3(0.05f + 1.95f * rng.next_float(), 0.05f + 1.95f * rng.next_float(),
                                    0.05f + 1.95f * rng.next_float())});
  }
  return w;
}

struct Reference {
  std::vector<glm::dvec3> value;      // base + sum_k w_k pane_k, 0 outside the panes
  std::vector<glm::dvec3> magnitude;  // sum_k |w_k| |pane_k|: the scale of the half error
};

Reference cpu_sum(const gi::Prm& prm, std::span<const gi::ClusterWeight> selected,
                  std::span<const glm::vec3> base = {}) {
  const std::size_t atlas = static_cast<std::size_t>(prm.width * prm.height);
  Reference r{std::vector<glm::dvec3>(atlas, glm::dvec3(0.0)), std::vector<glm::dvec3>(atlas, glm::dvec3(0.0))};
  const std::size_t n = prm.texels.size();
  const std::vector<float> panes = gi::dense_panes(prm);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = prm.texels[i];
    if (!base.empty()) r.value[t] = glm::dvec3(base[t]);
    for (const gi::ClusterWeight& w : selected)
      for (int ch = 0; ch < 3; ++ch) {
        const double p = panes[(w.cluster * n + i) * 3 + static_cast<std::size_t>(ch)];
        r.value[t][ch] += double(w.weight[ch]) * p;
        r.magnitude[t][ch] += std::abs(double(w.weight[ch]) * p);
      }
  }
  return r;
}

// Largest |gpu - ref| / (rel x magnitude + abs) over all texels and channels: <= 1 passes.
double worst_error_ratio(const std::vector<glm::vec3>& gpu, const Reference& ref, double* max_relative = nullptr) {
  EXPECT_EQ(gpu.size(), ref.value.size());
  double worst = 0.0;
  double worst_rel = 0.0;
  for (std::size_t t = 0; t < std::min(gpu.size(), ref.value.size()); ++t)
    for (int ch = 0; ch < 3; ++ch) {
      const double err = std::abs(double(gpu[t][ch]) - ref.value[t][ch]);
      worst = std::max(worst, err / (kRelativeTolerance * ref.magnitude[t][ch] + kAbsoluteTolerance));
      if (ref.magnitude[t][ch] > 0.0) worst_rel = std::max(worst_rel, err / ref.magnitude[t][ch]);
    }
  if (max_relative != nullptr) *max_relative = worst_rel;
  return worst;
}

std::vector<bool> pane_mask(const gi::Prm& prm) {
  std::vector<bool> m(static_cast<std::size_t>(prm.width * prm.height), false);
  for (std::uint32_t t : prm.texels) m[t] = true;
  return m;
}

TEST(PrmGpuPass, MatchesCpuSumWithinHalfPrecision) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  EXPECT_EQ(pass->pane_buffer_count(), 1u);
  EXPECT_NE(pass->texture(), 0u);
  // Half panes: 6 bytes per element and pane.
  EXPECT_GE(pass->gpu_bytes(), prm.texels.size() * 6 * 20);
  for (int k : {1, 7, 20}) {
    const auto selected = pick(20, k, static_cast<std::uint64_t>(k));
    ASSERT_TRUE(pass->run(selected).ok());
    double rel = 0.0;
    EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, selected), &rel), 1.0) << "K = " << k;
    std::printf("K = %d: max |gpu - cpu| / sum_k |w_k pane_k| = %.3g\n", k, rel);
  }
}

TEST(PrmGpuPass, TexelsOutsideThePanesStayZero) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  ASSERT_TRUE(pass->run(pick(20, 20, 3)).ok());
  const auto atlas = pass->read_back();
  const auto mask = pane_mask(prm);
  std::size_t outside = 0;
  for (std::size_t t = 0; t < atlas.size(); ++t) {
    if (mask[t]) {
      EXPECT_GT(atlas[t].x, 0.0f) << "pane texel " << t;
      continue;
    }
    ++outside;
    EXPECT_EQ(atlas[t], glm::vec3(0.0f)) << "texel " << t << " is outside the panes";
  }
  EXPECT_GT(outside, 100u);  // the synthetic subset leaves about a third out
}

TEST(PrmGpuPass, NoClustersSelectedGivesZeros) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  ASSERT_TRUE(pass->run(pick(20, 5, 1)).ok());  // something to overwrite
  ASSERT_TRUE(pass->run({}).ok());
  for (const glm::vec3& v : pass->read_back()) ASSERT_EQ(v, glm::vec3(0.0f));
}

TEST(PrmGpuPass, RerunOverwritesInsteadOfAccumulating) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  const auto first = pick(20, 12, 5);
  const auto second = pick(20, 3, 11);
  ASSERT_TRUE(pass->run(first).ok());
  ASSERT_TRUE(pass->run(second).ok());
  EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, second)), 1.0);
  ASSERT_TRUE(pass->run(second).ok());
  EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, second)), 1.0);
}

TEST(PrmGpuPass, AddsTheBaseAtlasAtPaneTexels) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  std::vector<glm::vec3> base(static_cast<std::size_t>(37 * 23));
  for (std::size_t t = 0; t < base.size(); ++t) {
    gi::Pcg32 rng = gi::Pcg32::for_item(99, t);
    base[t] = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 10.0f;
  }
  ASSERT_TRUE(pass->set_base(base).ok());
  const auto selected = pick(20, 6, 2);
  ASSERT_TRUE(pass->run(selected).ok());
  auto atlas = pass->read_back();
  EXPECT_LE(worst_error_ratio(atlas, cpu_sum(prm, selected, base)), 1.0);
  // K = 0 with a base: exactly the base at pane texels, 0 elsewhere.
  ASSERT_TRUE(pass->run({}).ok());
  atlas = pass->read_back();
  const auto mask = pane_mask(prm);
  for (std::size_t t = 0; t < atlas.size(); ++t) ASSERT_EQ(atlas[t], mask[t] ? base[t] : glm::vec3(0.0f)) << t;
  // Removing the base.
  ASSERT_TRUE(pass->set_base({}).ok());
  ASSERT_TRUE(pass->run(selected).ok());
  EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, selected)), 1.0);
}

TEST(PrmGpuPass, SplitsPanesOverSeveralBuffersAboveTheLimit) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  const std::size_t pane_bytes = dense_pane_chunks(prm) * 48;  // whole blocks of 8 elements (three uvec4s)
  auto pass = gi::PrmGpuPass::create(prm, {.max_buffer_bytes = 3 * pane_bytes + 8});
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  EXPECT_EQ(pass->pane_buffer_count(), 7u);  // 3 whole panes per buffer
  std::vector<glm::vec3> base(static_cast<std::size_t>(37 * 23), glm::vec3(0.5f, 0.25f, 2.0f));
  for (int k : {1, 4, 20}) {
    const auto selected = pick(20, k, 13);
    ASSERT_TRUE(pass->run(selected).ok());
    EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, selected)), 1.0) << "K = " << k;
    ASSERT_TRUE(pass->set_base(base).ok());
    ASSERT_TRUE(pass->run(selected).ok());
    EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, selected, base)), 1.0) << "K = " << k << ", base";
    ASSERT_TRUE(pass->set_base({}).ok());
  }
  // The same as the unsplit pass.
  auto whole = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(whole.ok()) << whole.error().to_string();
  const auto all = pick(20, 20, 4);
  ASSERT_TRUE(pass->run(all).ok());
  ASSERT_TRUE(whole->run(all).ok());
  const auto a = pass->read_back();
  const auto b = whole->read_back();
  const auto ref = cpu_sum(prm, all);
  for (std::size_t t = 0; t < a.size(); ++t)
    for (int ch = 0; ch < 3; ++ch)
      ASSERT_NEAR(a[t][ch], b[t][ch], 1e-5 * ref.magnitude[t][ch]) << t;  // only the summation order differs
}

TEST(PrmGpuPass, WideDynamicRangeKeepsRelativePrecision) {
  auto ctx = headless_or_fail();
  // Above the half range (65504) and below its normal range (6e-5): the per-pane scale
  // keeps both at full half precision.
  const gi::Prm big = synthetic_prm(37, 23, 4, 1e4f, 1e7f, 21);
  const gi::Prm small = synthetic_prm(37, 23, 4, 1e-9f, 1e-6f, 22);
  for (const gi::Prm* prm : {&big, &small}) {
    auto pass = gi::PrmGpuPass::create(*prm);
    ASSERT_TRUE(pass.ok()) << pass.error().to_string();
    const auto selected = pick(4, 4, 1);
    ASSERT_TRUE(pass->run(selected).ok());
    const Reference ref = cpu_sum(*prm, selected);
    const auto gpu = pass->read_back();
    for (std::size_t t = 0; t < gpu.size(); ++t)
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_NEAR(gpu[t][ch], ref.value[t][ch], kRelativeTolerance * ref.magnitude[t][ch]) << t;
  }
}

TEST(PrmGpuPass, WrapsWorkGroupsIntoATwoDimensionalGrid) {
  auto ctx = headless_or_fail();
  // Real atlases reach the 65535 groups of one dimension above 8 x 64 x 65535 texels; the
  // test hook wraps after 2 groups instead, so 61 x 29 (~1180 texels, 3 groups of 512) needs
  // a 2 x 2 grid whose last group is out of range. Integer panes up to 1024 are exact in
  // half, so the sum must be exact.
  gi::Prm prm = synthetic_prm(61, 29, 2);
  std::vector<float> dense = gi::dense_panes(prm);
  for (std::size_t f = 0; f < dense.size(); ++f) dense[f] = static_cast<float>(f % 1024) + 1.0f;
  gi::set_dense_panes(prm, dense);
  auto pass = gi::PrmGpuPass::create(prm, {.max_groups_x = 2});
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  const std::vector<gi::ClusterWeight> w{{1, glm::vec3(1.0f, 2.0f, 0.5f)}};
  ASSERT_TRUE(pass->run(w).ok());
  const auto atlas = pass->read_back();
  const std::size_t n = prm.texels.size();
  ASSERT_GT(n, 2u * 512u);
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = &dense[(n + i) * 3];
    ASSERT_EQ(atlas[prm.texels[i]], glm::vec3(p[0] * 1.0f, p[1] * 2.0f, p[2] * 0.5f)) << "element " << i;
  }
}

TEST(PrmGpuPass, RejectsInconsistentInput) {
  auto ctx = headless_or_fail();
  const gi::Prm good = synthetic_prm(37, 23, 20);
  {
    gi::Prm p = good;
    p.panes.values.pop_back();
    auto pass = gi::PrmGpuPass::create(p);
    ASSERT_FALSE(pass.ok());
    EXPECT_NE(pass.error().message.find("panes hold"), std::string::npos) << pass.error().to_string();
  }
  {
    gi::Prm p = good;
    std::swap(p.texels[3], p.texels[4]);
    auto pass = gi::PrmGpuPass::create(p);
    ASSERT_FALSE(pass.ok());
    EXPECT_NE(pass.error().message.find("ascending"), std::string::npos) << pass.error().to_string();
  }
  {
    gi::Prm p = good;
    p.texels.back() = 37 * 23;
    EXPECT_FALSE(gi::PrmGpuPass::create(p).ok());
  }
  {
    gi::Prm p = good;
    p.panes.values[100] = std::nanf("");
    EXPECT_FALSE(gi::PrmGpuPass::create(p).ok());
  }
  {
    auto pass = gi::PrmGpuPass::create(good, {.max_buffer_bytes = 1024});
    ASSERT_FALSE(pass.ok());
    EXPECT_NE(pass.error().message.find("above the buffer limit"), std::string::npos) << pass.error().to_string();
  }
  {
    // The weights travel in one buffer texture of at most the buffer limit: 16 bytes each.
    // One per selected block: a cluster of these dense panes stores a block on every tile.
    const std::size_t pane_bytes = dense_pane_chunks(good) * 48;
    auto small = gi::PrmGpuPass::create(good, {.max_buffer_bytes = pane_bytes});
    ASSERT_TRUE(small.ok()) << small.error().to_string();
    const std::size_t blocks = good.panes.tiles.tiles();
    std::vector<gi::ClusterWeight> many(pane_bytes / 16 / blocks, gi::ClusterWeight{1, glm::vec3(0.5f)});
    EXPECT_TRUE(small->run(many).ok());
    many.push_back(many.back());
    const auto refused = small->run(many);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("above the weight buffer's limit"), std::string::npos)
        << refused.error().to_string();
  }
  auto pass = gi::PrmGpuPass::create(good);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  const std::vector<gi::ClusterWeight> bad{{20, glm::vec3(1.0f)}};
  EXPECT_FALSE(pass->run(bad).ok());
  EXPECT_FALSE(pass->set_base(std::vector<glm::vec3>(10)).ok());
}

TEST(PrmGpuPass, MovesOwnership) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto created = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(created.ok()) << created.error().to_string();
  gi::PrmGpuPass pass = std::move(created).value();
  const std::uint32_t texture = pass.texture();
  gi::PrmGpuPass moved = std::move(pass);
  EXPECT_EQ(pass.texture(), 0u);  // NOLINT(bugprone-use-after-move): the moved-from state is specified
  EXPECT_EQ(moved.texture(), texture);
  const auto selected = pick(20, 9, 8);
  ASSERT_TRUE(moved.run(selected).ok());
  EXPECT_LE(worst_error_ratio(moved.read_back(), cpu_sum(prm, selected)), 1.0);
}

// The shared-exponent encoding (RGB9E5, 4 bytes per element): its CPU twin is gi::sum_panes
// over decoded_panes, so the GPU sum must equal the CPU sum of the decoded panes up to float
// summation order; the decoded panes lie within 2^-9 (1 + 2^-9) of each element's largest
// channel of the float panes.
gi::Prm with_decoded_panes(const gi::Prm& prm, gi::PrmPaneEncoding encoding) {
  gi::Prm out = prm;
  auto panes = gi::decoded_panes(prm, encoding);
  EXPECT_TRUE(panes.ok()) << panes.error().to_string();
  if (panes) out.panes = std::move(panes).value();
  return out;
}

TEST(PrmGpuPass, SharedExponentPanesStayWithinTheirBound) {
  for (const auto& [lo, hi] : {std::pair{1e-3f, 1e2f}, std::pair{1e4f, 1e7f}, std::pair{1e-9f, 1e-6f}}) {
    const gi::Prm prm = synthetic_prm(37, 23, 4, lo, hi, 31);
    const gi::Prm q = with_decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent);
    ASSERT_EQ(q.panes.values.size(), prm.panes.values.size());
    const std::vector<float> fp = gi::dense_panes(prm), qp = gi::dense_panes(q);
    double worst = 0.0;
    std::size_t changed = 0;
    for (std::size_t e = 0; e < fp.size() / 3; ++e) {
      const float* v = &fp[3 * e];
      const float top = std::max({v[0], v[1], v[2]});
      for (int ch = 0; ch < 3; ++ch) {
        const double err = std::abs(double(qp[3 * e + ch]) - double(v[ch]));
        worst = std::max(worst, err / double(top));
        changed += qp[3 * e + ch] != v[ch];
      }
    }
    std::printf("values in [%g, %g]: max |decoded - float| / element's largest channel %.3g\n", double(lo), double(hi),
                worst);
    EXPECT_LE(worst, std::ldexp(1.0, -9) * (1.0 + std::ldexp(1.0, -9)));
    EXPECT_GT(changed, fp.size() / 2);  // it does round: not a copy of the float panes
  }
  // Halves decode within 2^-11 of each value.
  const gi::Prm prm = synthetic_prm(37, 23, 4);
  const gi::Prm h = with_decoded_panes(prm, gi::PrmPaneEncoding::Half);
  for (std::size_t f = 0; f < prm.panes.values.size(); ++f)
    ASSERT_LE(std::abs(h.panes.values[f] - prm.panes.values[f]), std::ldexp(1.0f, -11) * prm.panes.values[f]) << f;
}

TEST(PrmGpuPass, SharedExponentMatchesItsCpuTwin) {
  auto ctx = headless_or_fail();
  for (const auto& [lo, hi] : {std::pair{1e-3f, 1e2f}, std::pair{1e4f, 1e7f}, std::pair{1e-9f, 1e-6f}}) {
    const gi::Prm prm = synthetic_prm(37, 23, 20, lo, hi, 41);
    auto pass = gi::PrmGpuPass::create(prm, {.encoding = gi::PrmPaneEncoding::SharedExponent});
    ASSERT_TRUE(pass.ok()) << pass.error().to_string();
    EXPECT_EQ(pass->pane_bytes(), 20 * (dense_pane_chunks(prm)) * 32);  // 4 bytes per element
    const gi::Prm twin = with_decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent);
    std::vector<glm::vec3> base(static_cast<std::size_t>(37 * 23), glm::vec3(0.5f, 0.25f, 2.0f) * hi);
    for (int k : {1, 7, 20}) {
      const auto selected = pick(20, k, static_cast<std::uint64_t>(k) + 3);
      ASSERT_TRUE(pass->run(selected).ok());
      const Reference ref = cpu_sum(twin, selected);
      const auto gpu = pass->read_back();
      for (std::size_t t = 0; t < gpu.size(); ++t)
        for (int ch = 0; ch < 3; ++ch)
          ASSERT_NEAR(gpu[t][ch], ref.value[t][ch], 1e-5 * ref.magnitude[t][ch]) << "K = " << k << ", texel " << t;
      ASSERT_TRUE(pass->set_base(base).ok());
      ASSERT_TRUE(pass->run(selected).ok());
      const Reference with_base = cpu_sum(twin, selected, base);
      const auto gpu_base = pass->read_back();
      for (std::size_t t = 0; t < gpu.size(); ++t)
        for (int ch = 0; ch < 3; ++ch)
          ASSERT_NEAR(gpu_base[t][ch], with_base.value[t][ch],
                      1e-5 * (with_base.magnitude[t][ch] + std::abs(with_base.value[t][ch])))
              << "K = " << k << ", base, texel " << t;
      ASSERT_TRUE(pass->set_base({}).ok());
    }
  }
}

TEST(PrmGpuPass, SharedExponentRejectsNegativePaneValues) {
  auto ctx = headless_or_fail();
  gi::Prm prm = synthetic_prm(37, 23, 4);
  std::vector<float> dense = gi::dense_panes(prm);
  dense[3 * prm.texels.size() + 5] = -1.0f;  // pane 1, element 1, G
  gi::set_dense_panes(prm, dense);
  EXPECT_TRUE(gi::PrmGpuPass::create(prm).ok()) << "halves hold negative values";
  auto pass = gi::PrmGpuPass::create(prm, {.encoding = gi::PrmPaneEncoding::SharedExponent});
  ASSERT_FALSE(pass.ok());
  EXPECT_NE(pass.error().message.find("is negative"), std::string::npos) << pass.error().to_string();
  EXPECT_FALSE(gi::decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent).ok());
}

TEST(PrmGpuPass, HalfPanesMatchTheirCpuTwinUpToSummationOrder) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = synthetic_prm(37, 23, 20);
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  EXPECT_EQ(pass->pane_bytes(), 20 * (dense_pane_chunks(prm)) * 48);  // 6 bytes per element
  const gi::Prm twin = with_decoded_panes(prm, gi::PrmPaneEncoding::Half);
  const auto selected = pick(20, 20, 9);
  ASSERT_TRUE(pass->run(selected).ok());
  const Reference ref = cpu_sum(twin, selected);
  const auto gpu = pass->read_back();
  for (std::size_t t = 0; t < gpu.size(); ++t)
    for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(gpu[t][ch], ref.value[t][ch], 1e-5 * ref.magnitude[t][ch]) << t;
}

}  // namespace

namespace {

// Sparse panes (issue 38): cluster c lights a disc around (6 + 10c, 10) of a 64 x 24 atlas,
// zeros elsewhere, so each stores only the 8 x 8 tiles under its disc.
gi::Prm disc_prm() {
  gi::Prm prm;
  prm.width = 64;
  prm.height = 24;
  prm.cluster_count = 6;
  prm.cluster_size.assign(6, 1);
  for (std::uint32_t t = 0; t < 64u * 24u; ++t)
    if (t % 5 != 2) prm.texels.push_back(t);
  const std::size_t n = prm.texels.size();
  std::vector<float> dense(6 * n * 3, 0.0f);
  for (std::size_t c = 0; c < 6; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      const float dx = static_cast<float>(prm.texels[i] % 64) - (6.0f + 10.0f * static_cast<float>(c));
      const float dy = static_cast<float>(prm.texels[i] / 64) - 10.0f;
      if (dx * dx + dy * dy < 25.0f)
        for (std::size_t ch = 0; ch < 3; ++ch)
          dense[(c * n + i) * 3 + ch] = 1.0f + static_cast<float>((i + ch + c) % 17);
    }
  gi::set_dense_panes(prm, dense);
  return prm;
}

// Chunks of the tiles `clusters` store blocks on (each tile once).
std::size_t lit_chunks(const gi::Prm& prm, std::initializer_list<std::uint32_t> clusters) {
  std::vector<bool> lit(prm.panes.tiles.tiles(), false);
  for (std::uint32_t c : clusters)
    for (std::uint32_t b = prm.panes.cluster_first[c]; b < prm.panes.cluster_first[c + 1]; ++b)
      lit[prm.panes.blocks[b]] = true;
  std::size_t chunks = 0;
  for (std::size_t k = 0; k < lit.size(); ++k)
    if (lit[k]) chunks += (prm.panes.tiles.size(k) + 7) / 8;
  return chunks;
}

}  // namespace

TEST(PrmGpuPass, SparsePanesWriteOnlyTheLitTilesAndMatchTheCpuTwin) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = disc_prm();
  EXPECT_LT(prm.panes.blocks.size(), 6u * prm.panes.tiles.tiles() / 2) << "most tiles are dark for every cluster";
  auto pass = gi::PrmGpuPass::create(prm);
  ASSERT_TRUE(pass.ok()) << pass.error().to_string();
  EXPECT_EQ(pass->pane_bytes(), 48 * (lit_chunks(prm, {0}) + lit_chunks(prm, {1}) + lit_chunks(prm, {2}) +
                                      lit_chunks(prm, {3}) + lit_chunks(prm, {4}) + lit_chunks(prm, {5})));
  std::vector<glm::vec3> base(64 * 24);
  for (std::size_t t = 0; t < base.size(); ++t) base[t] = glm::vec3(0.25f, 0.5f, static_cast<float>(t % 7));
  ASSERT_TRUE(pass->set_base(base).ok());
  const std::vector<gi::ClusterWeight> a{{0, glm::vec3(1.0f, 0.5f, 2.0f)}, {1, glm::vec3(0.25f)}};
  const std::vector<gi::ClusterWeight> b{{4, glm::vec3(3.0f, 1.0f, 0.5f)}};
  const std::vector<gi::ClusterWeight> a_again{{0, glm::vec3(2.0f)}, {1, glm::vec3(0.5f)}};
  ASSERT_TRUE(pass->run(a).ok());  // the first run writes every tile (the base everywhere)
  EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, a, base)), 1.0);
  ASSERT_TRUE(pass->run(b).ok());  // a's tiles go back to the base, b's are lit
  EXPECT_EQ(pass->last_run_chunks(), lit_chunks(prm, {0, 1, 4}));
  EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, b, base)), 1.0);
  ASSERT_TRUE(pass->run(a_again).ok());
  EXPECT_EQ(pass->last_run_chunks(), lit_chunks(prm, {0, 1, 4}));
  ASSERT_TRUE(pass->run(a_again).ok());  // the same clusters: only their own tiles
  EXPECT_EQ(pass->last_run_chunks(), lit_chunks(prm, {0, 1}));
  EXPECT_LT(pass->last_run_chunks(), lit_chunks(prm, {0, 1, 2, 3, 4, 5}));
  EXPECT_LE(worst_error_ratio(pass->read_back(), cpu_sum(prm, a_again, base)), 1.0);
  ASSERT_TRUE(pass->run({}).ok());
  const auto back = pass->read_back();
  const auto mask = pane_mask(prm);
  for (std::size_t t = 0; t < back.size(); ++t) ASSERT_EQ(back[t], mask[t] ? base[t] : glm::vec3(0.0f)) << t;
  // The shared-exponent pass reads the same blocks.
  auto rgb9e5 = gi::PrmGpuPass::create(prm, {.encoding = gi::PrmPaneEncoding::SharedExponent});
  ASSERT_TRUE(rgb9e5.ok()) << rgb9e5.error().to_string();
  const gi::Prm twin = with_decoded_panes(prm, gi::PrmPaneEncoding::SharedExponent);
  ASSERT_TRUE(rgb9e5->run(b).ok());
  ASSERT_TRUE(rgb9e5->run(a).ok());
  const Reference ref = cpu_sum(twin, a);
  const auto gpu = rgb9e5->read_back();
  for (std::size_t t = 0; t < gpu.size(); ++t)
    for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(gpu[t][ch], ref.value[t][ch], 1e-5 * ref.magnitude[t][ch]) << t;
}

namespace {

// A PRM whose panes are coarser than its atlas (issue 38): the Cornell box's charts at 8
// texels per metre for the panes, read at 16 (the atlas), six clusters of pseudo-random
// values in [0.01, 1] over the coarse layout's valid texels.
gi::Prm coarse_prm() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset.ok()) << asset.error().to_string();
  const gi::BakeInput input = gi::bake_input_from(asset.value());
  const auto inputs = gi::atlas_inputs_from(input);
  auto coarse = gi::build_atlas_layout(inputs, {.texels_per_metre = 8.0f});
  auto fine = gi::build_atlas_layout(inputs, {.texels_per_metre = 16.0f});
  EXPECT_TRUE(coarse.ok() && fine.ok());
  gi::Prm prm;
  prm.layout = std::move(coarse).value();
  prm.width = prm.layout.width;
  prm.height = prm.layout.height;
  prm.settings.texels_per_metre = 16.0f;
  prm.settings.pane_texels_per_metre = 8.0f;
  const gi::AtlasTexels texels = gi::rasterize_atlas(prm.layout, inputs);
  for (std::size_t t = 0; t < texels.valid.size(); ++t)
    if (texels.valid[t]) prm.texels.push_back(static_cast<std::uint32_t>(t));
  prm.cluster_count = 6;
  prm.cluster_size.assign(6, 1);
  std::vector<float> dense(6 * prm.texels.size() * 3);
  for (std::size_t f = 0; f < dense.size(); ++f) dense[f] = 0.01f + 0.99f * gi::Pcg32::for_item(11, f).next_float();
  gi::set_dense_panes(prm, dense);
  auto read = gi::prm_atlas_read(prm, std::move(fine).value(), input);
  EXPECT_TRUE(read.ok()) << read.error().to_string();
  prm.atlas = std::move(read).value();
  return prm;
}

// The CPU twin of a coarse pass: base at the texels the upsampler writes, plus the
// upsampled K-sum (sum_panes).
std::vector<glm::vec3> coarse_twin(const gi::Prm& prm, std::span<const gi::ClusterWeight> selected,
                                   std::span<const glm::vec3> base) {
  std::vector<glm::vec3> out = gi::sum_panes(prm, selected);
  for (std::uint32_t t : prm.atlas->upsampler->fine_texels()) out[t] += base[t];
  return out;
}

}  // namespace

// Coarse panes: the pass sums at the pane layout, then upsamples with the PaneUpsampler's
// taps into the atlas. Its output equals the CPU twin (sum_panes over the decoded panes, then
// the same taps) up to float summation order, and the float panes' sum within half
// precision; a later run with fewer clusters leaves no stale light; the base lies at every
// texel the upsampler writes (valid texels and gutter rings), 0 elsewhere.
TEST(PrmGpuPass, CoarsePanesAreUpsampledIntoTheAtlasLikeTheCpuTwin) {
  auto ctx = headless_or_fail();
  const gi::Prm prm = coarse_prm();
  const auto fine_size = static_cast<std::size_t>(prm.atlas_width() * prm.atlas_height());
  ASSERT_GE(fine_size, static_cast<std::size_t>(2 * prm.width * prm.height));
  std::vector<glm::vec3> base(fine_size);
  for (std::size_t t = 0; t < base.size(); ++t) base[t] = glm::vec3(0.25f, 0.5f, static_cast<float>(t % 5));
  const std::vector<gi::ClusterWeight> a{{0, glm::vec3(1.0f, 0.5f, 2.0f)}, {3, glm::vec3(0.25f)}};
  const std::vector<gi::ClusterWeight> b{{5, glm::vec3(3.0f, 1.0f, 0.5f)}};
  for (const gi::PrmPaneEncoding encoding : {gi::PrmPaneEncoding::Half, gi::PrmPaneEncoding::SharedExponent}) {
    SCOPED_TRACE(encoding == gi::PrmPaneEncoding::Half ? "half" : "rgb9e5");
    auto pass = gi::PrmGpuPass::create(prm, {.encoding = encoding});
    ASSERT_TRUE(pass.ok()) << pass.error().to_string();
    EXPECT_TRUE(pass->upsamples());
    // Issue 38's compact records: 16 bytes per read, 8 per ring texel; the parts add up.
    EXPECT_EQ(pass->memory().upsample, prm.atlas->upsampler->gpu_bytes());
    EXPECT_EQ(pass->memory().total(), pass->gpu_bytes());
    EXPECT_EQ(pass->memory().output, fine_size * 16);
    EXPECT_EQ(pass->width(), prm.atlas_width());
    EXPECT_EQ(pass->height(), prm.atlas_height());
    ASSERT_TRUE(pass->set_base(base).ok());
    const gi::Prm twin = with_decoded_panes(prm, encoding);
    for (const auto* selected : {&a, &b, &a}) {
      ASSERT_TRUE(pass->run(*selected).ok());
      const std::vector<glm::vec3> gpu = pass->read_back();
      const std::vector<glm::vec3> cpu = coarse_twin(twin, *selected, base);
      const std::vector<glm::vec3> exact = coarse_twin(prm, *selected, base);
      ASSERT_EQ(gpu.size(), cpu.size());
      double worst_twin = 0.0, worst_float = 0.0;
      for (std::size_t t = 0; t < gpu.size(); ++t) {
        // RGB9E5 rounds each channel to a step of the element's largest: its error is
        // relative to the texel's largest channel.
        const float top = std::max({exact[t].x, exact[t].y, exact[t].z});
        for (int ch = 0; ch < 3; ++ch) {
          const double scale = encoding == gi::PrmPaneEncoding::Half ? double(exact[t][ch]) : double(top);
          worst_twin = std::max(worst_twin, double(std::abs(gpu[t][ch] - cpu[t][ch])) / (double(cpu[t][ch]) + 1e-6));
          worst_float = std::max(worst_float, double(std::abs(gpu[t][ch] - exact[t][ch])) / (scale + 1e-6));
        }
      }
      std::printf("coarse panes, K = %zu: max relative |gpu - twin| %.3g, |gpu - float panes| %.3g\n", selected->size(),
                  worst_twin, worst_float);
      EXPECT_LE(worst_twin, 1e-5);
      // Half floats: 2^-11 of each (non-negative) value; RGB9E5: 2e-3 of each element's largest
      // channel, times the weights' spread over channels (up to 8 here).
      EXPECT_LE(worst_float, encoding == gi::PrmPaneEncoding::Half ? kRelativeTolerance : 2e-2);
    }
    ASSERT_TRUE(pass->run({}).ok());
    const std::vector<glm::vec3> back = pass->read_back();
    std::vector<bool> written(fine_size, false);
    for (std::uint32_t t : prm.atlas->upsampler->fine_texels()) written[t] = true;
    for (std::size_t t = 0; t < back.size(); ++t) ASSERT_EQ(back[t], written[t] ? base[t] : glm::vec3(0.0f)) << t;
  }
}
