// Bundle I/O: the checksum every bundle file is verified with on load, against memcpy of
// the same bytes (the yardstick: a checksum cannot be cheaper than reading the bytes once).
//   ./build/gi/benchmarks/io_bench
// The demo level's medium bundle is about 15 MB, so bytes/s here says what a load pays.
#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#include "io/content_hash.h"

namespace {

std::vector<unsigned char> payload(std::size_t n) {
  std::vector<unsigned char> v(n);
  std::uint32_t x = 12345u;
  for (unsigned char& c : v) c = static_cast<unsigned char>((x = x * 1664525u + 1013904223u) >> 24);
  return v;
}

void BM_Memcpy(benchmark::State& state) {
  const auto src = payload(static_cast<std::size_t>(state.range(0)));
  std::vector<unsigned char> dst(src.size());
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), src.size());
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}

void BM_ContentHash(benchmark::State& state) {
  const auto src = payload(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    gi::ContentHash h;
    h.add_bytes(src.data(), src.size());
    benchmark::DoNotOptimize(h.value());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}

// The geometry hash feeds values one float at a time: the per-call cost of the stream.
void BM_ContentHashPerFloat(benchmark::State& state) {
  std::vector<float> src(static_cast<std::size_t>(state.range(0)) / sizeof(float));
  for (std::size_t i = 0; i < src.size(); ++i) src[i] = static_cast<float>(i) * 0.001f;
  for (auto _ : state) {
    gi::ContentHash h;
    for (float f : src) h.add_value(f);
    benchmark::DoNotOptimize(h.value());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}

}  // namespace

BENCHMARK(BM_Memcpy)->Arg(16 << 20);
BENCHMARK(BM_ContentHash)->Arg(16 << 20);
BENCHMARK(BM_ContentHashPerFloat)->Arg(1 << 20);
BENCHMARK_MAIN();
