// The PRM pane sum on the GPU (PrmGpuPass::run): milliseconds per run for T pane texels and K
// selected clusters, with glFinish inside the timed region (DESIGN.md §4: on llvmpipe these
// are CPU timings; compare them as ratios). Counters: pane texel x cluster products per
// second and the half-float pane bytes read per second.
//   ./build/benchmarks/prm_gpu_bench --benchmark_counters_tabular=true
#include <GL/glcorearb.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <engine/gpu/context.h>

#include "bench_gl.h"

#include "core/random.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
#include "prm/prm_runtime.h"

namespace {

constexpr int kClusters = 128;  // the largest K benchmarked
constexpr int kAtlasWidth = 1024;


// T pane texels: every other texel of a 1024-wide atlas; 128 clusters of pane values in (0, 10).
gi::Prm synthetic_prm(std::size_t texels) {
  gi::Prm prm;
  prm.width = kAtlasWidth;
  prm.height = static_cast<int>((2 * texels + kAtlasWidth - 1) / kAtlasWidth);
  prm.cluster_count = kClusters;
  prm.texels.resize(texels);
  for (std::size_t i = 0; i < texels; ++i) prm.texels[i] = static_cast<std::uint32_t>(2 * i);
  prm.panes.resize(static_cast<std::size_t>(kClusters) * texels * 3);
  gi::Pcg32 rng(5, 1);
  for (float& v : prm.panes) v = 10.0f * rng.next_float();
  return prm;
}

gi::PrmGpuPass& pass_for(std::size_t texels) {
  static std::map<std::size_t, std::unique_ptr<gi::PrmGpuPass>> passes;
  bench::gl_context();
  auto& p = passes[texels];
  if (!p) {
    auto created = gi::PrmGpuPass::create(synthetic_prm(texels));
    if (!created) {
      std::fprintf(stderr, "%s\n", created.error().to_string().c_str());
      std::exit(1);
    }
    p = std::make_unique<gi::PrmGpuPass>(std::move(created).value());
  }
  return *p;
}

void BM_PrmGpuSum(benchmark::State& state) {
  const auto texels = static_cast<std::size_t>(state.range(0));
  const auto k = static_cast<int>(state.range(1));
  gi::PrmGpuPass& pass = pass_for(texels);
  std::vector<gi::ClusterWeight> selected;
  for (int i = 0; i < k; ++i)
    selected.push_back({static_cast<std::uint32_t>(i * (kClusters / k)), glm::vec3(0.5f, 0.25f, 1.0f)});
  (void)pass.run(selected);  // warm-up: first-dispatch shader compilation in llvmpipe
  glFinish();
  for (auto _ : state) {
    if (!pass.run(selected)) state.SkipWithError("PrmGpuPass::run failed");
    glFinish();
  }
  const double products = double(texels) * double(k) * double(state.iterations());
  state.counters["Mtexel_clusters/s"] = benchmark::Counter(products * 1e-6, benchmark::Counter::kIsRate);
  state.counters["pane_GB/s"] = benchmark::Counter(products * 6.0 * 1e-9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PrmGpuSum)
    ->ArgNames({"T", "K"})
    ->ArgsProduct({{64 << 10, 256 << 10}, {8, 32, 128}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
