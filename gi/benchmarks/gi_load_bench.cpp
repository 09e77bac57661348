// GISystem::load and the first GI frame against the yardstick of reading the bundle's bytes
// and decompressing them, measured in the same run (issue 34: load <= 2x the yardstick, the
// GPU upload of the first frame reported apart), on two scenes:
//   demo    assets/demo_level.gltf, its own lights
//   sponza  Dabrovic Sponza (GI_EXTERNAL_ASSETS_DIR, ../shared/external-assets by default),
//           untextured, under the sky and high sun of tools/check-real-level.sh (the scene
//           loaded gets the same sky and sun as the one baked, so the bundle's hashes match);
//           skipped when the asset is absent
//   ./build/gi/benchmarks/gi_load_bench --benchmark_counters_tabular=true
//   ./build/gi/benchmarks/gi_load_bench --benchmark_filter=sponza
// Each scene is baked at preview (every method its plan asks for) into the temporary
// directory once (gi_load_bench_<scene>_preview.gibake) and re-baked when it no longer
// loads (another format, other geometry). GI_LOAD_BENCH_SCENE + GI_LOAD_BENCH_BUNDLE replace
// the demo scene by any glTF and its bundle (lit as baked).
// Benchmarks, per scene:
//   BM_ReadBundleBytes  the yardstick: every file of the bundle read into memory; the EXR
//                       images decoded (engine::load_exr) and every zstd frame decompressed
//   BM_GISystemLoad     GISystem::load of the same bundle into a fresh instance of the scene
//                       (the scene's instantiation is outside the timing)
//   BM_FirstFrame       GISystem::frame() right after load: the GPU upload and the first
//                       composite (glFinish-timed; CPU time on llvmpipe)
// Counters: bundle_mb (bytes on disk).
#include <GL/glcorearb.h>
#include <engine/gltf.h>
#include <engine/image.h>
#include <engine/scene.h>
#include <engine/sky.h>
#include <engine/sun.h>
#include <gi/bake.h>
#include <gi/bake_input.h>
#include <gi/frame_truth.h>
#include <gi/gi_system.h>

#include <zstd.h>
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
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
  engine::SceneAsset asset;  ///< Lit as baked (Sponza: untextured, the sky and the sun set).
  fs::path bundle;
  std::uint64_t bundle_bytes = 0;
};

// tools/check-real-level.sh's sky and high sun (gi-bake --sky, --sun).
constexpr const char* kSponzaSky = "zenith:10,16,30;horizon:28,30,34;ground:6,6,6";
// (its disc's default radius as tools/common/sun_option.cpp computes it: 0.27 degrees)
const engine::Sun kSponzaHighSun{.direction = {0.25f, -1.0f, 0.15f},
                                 .irradiance = {700.0f, 650.0f, 600.0f},
                                 .angular_radius_rad = 0.27f * std::numbers::pi_v<float> / 180.0f};

fs::path sponza_path() {
  const char* dir = std::getenv("GI_EXTERNAL_ASSETS_DIR");
  const fs::path assets = dir ? fs::path(dir) : fs::path(GI_SOURCE_DIR) / ".." / "shared" / "external-assets";
  return assets / "dabrovic-sponza" / "sponza.gltf";
}

engine::SceneAsset load_scene(const fs::path& path) {
  auto asset = engine::load_gltf(path);
  if (!asset) fail(asset.error().to_string());
  return std::move(asset).value();
}

// Sponza as check-real-level bakes it: untextured, under its sky and high sun.
engine::SceneAsset lit_sponza() {
  engine::SceneAsset asset = gi::without_textures(load_scene(sponza_path()));
  const std::optional<engine::SkyText> sky = engine::parse_sky_text(kSponzaSky);
  if (!sky) fail("bad sky text");
  asset.environment.sky_radiance = sky->uniform;
  asset.environment.sky_gradient = sky->gradient;
  engine::set_sun(asset, kSponzaHighSun);
  return asset;
}

bool loads(const Fixture& f) {
  if (!fs::exists(f.bundle / "manifest.json")) return false;
  engine::Scene scene = engine::instantiate(f.asset);
  return gi::GISystem::load(f.bundle, scene).ok();
}

Fixture make_fixture(const std::string& name) {
  Fixture out;
  const char* scene = std::getenv("GI_LOAD_BENCH_SCENE");
  const char* bundle = std::getenv("GI_LOAD_BENCH_BUNDLE");
  if (name == "demo" && scene != nullptr) {
    if (bundle == nullptr) fail("GI_LOAD_BENCH_SCENE needs GI_LOAD_BENCH_BUNDLE (gi-bake's output for it)");
    out.asset = load_scene(scene);
    out.bundle = bundle;
  } else {
    out.asset = name == "sponza" ? lit_sponza() : load_scene(fs::path(GI_SOURCE_DIR) / "assets" / "demo_level.gltf");
    out.bundle = fs::temp_directory_path() / ("gi_load_bench_" + name + "_preview.gibake");
    if (!loads(out)) {
      engine::Scene s = engine::instantiate(out.asset);
      std::fprintf(stderr, "gi_load_bench: baking %s at preview into %s\n", name.c_str(), out.bundle.c_str());
      fs::remove_all(out.bundle);
      auto report = gi::bake_bundle(gi::bake_input_from(s), out.bundle, {.preset = "preview"});
      if (!report) fail(report.error().to_string());
    }
  }
  for (const auto& e : fs::directory_iterator(out.bundle))
    if (e.is_regular_file()) out.bundle_bytes += e.file_size();
  return out;
}

const Fixture& fixture(const std::string& name) {
  static std::map<std::string, Fixture> fixtures;
  auto it = fixtures.find(name);
  if (it == fixtures.end()) it = fixtures.emplace(name, make_fixture(name)).first;
  return it->second;
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

void BM_ReadBundleBytes(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
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

void BM_GISystemLoad(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
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

void BM_FirstFrame(benchmark::State& state, const std::string& name) {
  const Fixture& f = fixture(name);
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

int main(int argc, char** argv) {
  std::vector<std::string> scenes{"demo"};
  if (fs::exists(sponza_path())) scenes.emplace_back("sponza");
  for (const std::string& scene : scenes) {
    benchmark::RegisterBenchmark(("BM_ReadBundleBytes/" + scene).c_str(), BM_ReadBundleBytes, scene)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(2.0);
    benchmark::RegisterBenchmark(("BM_GISystemLoad/" + scene).c_str(), BM_GISystemLoad, scene)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(2.0);
    benchmark::RegisterBenchmark(("BM_FirstFrame/" + scene).c_str(), BM_FirstFrame, scene)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(2.0);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
