// The bakers' parallel loop (gi::ThreadPool::parallel_for) against raw oneTBB and a serial
// loop in the same run, on items of bake-like size (a few microseconds: one texel's shadow
// rays) and of tiny size (where per-item dispatch shows).
//   ./build/gi/benchmarks/parallel_bench
#include <benchmark/benchmark.h>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <cmath>
#include <vector>

#include "core/thread_pool.h"

namespace {

// `work` iterations of dependent arithmetic per item.
inline float kernel(std::size_t i, int work) {
  float x = static_cast<float>(i) * 1e-3f;
  for (int k = 0; k < work; ++k) x = std::sqrt(x * x + 1.0f) * 0.999f;
  return x;
}

void BM_Serial(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const int work = static_cast<int>(state.range(1));
  std::vector<float> out(n);
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) out[i] = kernel(i, work);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}

void BM_ThreadPool(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const int work = static_cast<int>(state.range(1));
  std::vector<float> out(n);
  gi::ThreadPool pool(2);
  for (auto _ : state) {
    pool.parallel_for(
        n, [&](std::size_t i) { out[i] = kernel(i, work); }, 16);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}

void BM_RawTbb(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const int work = static_cast<int>(state.range(1));
  std::vector<float> out(n);
  tbb::task_arena arena(2);
  for (auto _ : state) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) out[i] = kernel(i, work);
      });
    });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}

}  // namespace

// {items, work per item}: 64k items of ~2 us (a texel's rays), 1M tiny items.
BENCHMARK(BM_Serial)->Args({1 << 16, 400})->Args({1 << 20, 4})->UseRealTime();
BENCHMARK(BM_ThreadPool)->Args({1 << 16, 400})->Args({1 << 20, 4})->UseRealTime();
BENCHMARK(BM_RawTbb)->Args({1 << 16, 400})->Args({1 << 20, 4})->UseRealTime();
BENCHMARK_MAIN();
