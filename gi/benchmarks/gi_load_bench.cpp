// GISystem::load and the first GI frame against the yardstick of reading the bundle's bytes
// and decompressing them, measured in the same run (issue 34: load <= 2x the yardstick, the
// GPU upload of the first frame reported apart).
//   ./build/gi/benchmarks/gi_load_bench --benchmark_counters_tabular=true
//   GI_LOAD_BENCH_SCENE=../shared/external-assets/dabrovic-sponza/sponza.gltf
//     GI_LOAD_BENCH_BUNDLE=/tmp/sponza_preview.gibake ./build/gi/benchmarks/gi_load_bench
//   (the two variables on one command line)
// Without GI_LOAD_BENCH_SCENE the demo level (assets/demo_level.gltf) is baked at preview into
// a temporary directory first (every method its plan asks for) and loaded from there.
// Benchmarks:
//   BM_ReadBundleBytes  the yardstick: every file of the bundle read into memory; the EXR
//                       images decoded (engine::load_exr) and every zstd frame decompressed
//   BM_GISystemLoad     GISystem::load of the same bundle into a fresh instance of the scene
//                       (the scene's instantiation is outside the timing)
//   BM_FirstFrame       GISystem::frame() right after load: the GPU upload and the first
//                       composite (glFinish-timed; CPU time on llvmpipe)
// Counters: bundle_mb (bytes on disk), ms (median wall time of one run).
#include <GL/glcorearb.h>
#include <engine/gltf.h>
#include <engine/image.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/bake_input.h>
#include <gi/gi_system.h>

#include <zstd.h>
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_gl.h"

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "gi_load_bench: %s\n", what.c_str());
  std::exit(1);
}

struct Fixture {
  engine::SceneAsset asset;
  fs::path bundle;
  std::uint64_t bundle_bytes = 0;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture out;
    const char* scene = std::getenv("GI_LOAD_BENCH_SCENE");
    const char* bundle = std::getenv("GI_LOAD_BENCH_BUNDLE");
    const fs::path scene_path = scene ? fs::path(scene) : fs::path(GI_SOURCE_DIR) / "assets" / "demo_level.gltf";
    auto asset = engine::load_gltf(scene_path);
    if (!asset) fail(asset.error().to_string());
    out.asset = std::move(asset).value();
    if (bundle) {
      out.bundle = bundle;
    } else if (scene) {
      fail("GI_LOAD_BENCH_SCENE needs GI_LOAD_BENCH_BUNDLE (gi-bake's output for it)");
    } else {
      out.bundle = fs::temp_directory_path() / "gi_load_bench_demo_preview.gibake";
      if (!fs::exists(out.bundle / "manifest.json")) {
        engine::Scene s = engine::instantiate(out.asset);
        std::fprintf(stderr, "gi_load_bench: baking the demo level at preview into %s\n", out.bundle.c_str());
        auto report = gi::bake_bundle(gi::bake_input_from(s), out.bundle, {.preset = "preview"});
        if (!report) fail(report.error().to_string());
      }
    }
    for (const auto& e : fs::directory_iterator(out.bundle))
      if (e.is_regular_file()) out.bundle_bytes += e.file_size();
    return out;
  }();
  return f;
}

std::vector<char> read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The bytes of every zstd frame in `bytes` (frames start with 28 b5 2f fd), decompressed.
std::size_t decompress_frames(const std::vector<char>& bytes) {
  std::size_t out = 0;
  const unsigned char magic[4] = {0x28, 0xb5, 0x2f, 0xfd};
  for (std::size_t i = 0; i + 4 <= bytes.size(); ++i) {
    if (std::memcmp(bytes.data() + i, magic, 4) != 0) continue;
    const std::size_t avail = bytes.size() - i;
    const std::size_t frame = ZSTD_findFrameCompressedSize(bytes.data() + i, avail);
    if (ZSTD_isError(frame)) continue;
    const unsigned long long size = ZSTD_getFrameContentSize(bytes.data() + i, avail);
    if (size == ZSTD_CONTENTSIZE_UNKNOWN || size == ZSTD_CONTENTSIZE_ERROR) continue;
    std::vector<char> dst(size);
    const std::size_t got = ZSTD_decompress(dst.data(), dst.size(), bytes.data() + i, frame);
    if (ZSTD_isError(got)) fail("zstd: " + std::string(ZSTD_getErrorName(got)));
    benchmark::DoNotOptimize(dst.data());
    out += got;
    i += frame - 1;
  }
  return out;
}

void BM_ReadBundleBytes(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    std::size_t total = 0;
    for (const auto& e : fs::directory_iterator(f.bundle)) {
      if (!e.is_regular_file()) continue;
      if (e.path().extension() == ".exr") {
        auto image = engine::load_exr(e.path());
        if (!image) fail(image.error().to_string());
        total += image->pixels.size() * sizeof(float);
        continue;
      }
      const std::vector<char> bytes = read_all(e.path());
      total += bytes.size() + decompress_frames(bytes);
    }
    benchmark::DoNotOptimize(total);
  }
  state.counters["bundle_mb"] = static_cast<double>(f.bundle_bytes) / 1e6;
}

void BM_GISystemLoad(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    state.PauseTiming();
    engine::Scene scene = engine::instantiate(f.asset);
    state.ResumeTiming();
    auto gi = gi::GISystem::load(f.bundle, scene);
    if (!gi) fail(gi.error().to_string());
    state.PauseTiming();
    gi.value().reset();
    state.ResumeTiming();
  }
  state.counters["bundle_mb"] = static_cast<double>(f.bundle_bytes) / 1e6;
}

void BM_FirstFrame(benchmark::State& state) {
  const Fixture& f = fixture();
  (void)bench::gl_context();
  for (auto _ : state) {
    state.PauseTiming();
    engine::Scene scene = engine::instantiate(f.asset);
    auto gi = gi::GISystem::load(f.bundle, scene);
    if (!gi) fail(gi.error().to_string());
    state.ResumeTiming();
    (void)gi.value()->frame();
    glFinish();
    state.PauseTiming();
    gi.value().reset();
    state.ResumeTiming();
  }
}

}  // namespace

BENCHMARK(BM_ReadBundleBytes)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_GISystemLoad)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_FirstFrame)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_MAIN();
