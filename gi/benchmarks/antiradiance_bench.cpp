// Per-frame cost of the antiradiance region of assets/corridor.gltf (the door) at the
// preview bake settings (0.8 m elements, 64 bins): what a frame where the door moved costs,
// phase by phase. llvmpipe timings are CPU timings (DESIGN.md §4); GPU phases end in glFinish.
// BM_DoorMoveAtPreset (issue 37): one door move at a gi-bake preset's settings, from the bake
// as a load gets it, against re-baking the corridor's light atlas at the same preset in the
// same run (what a door without antiradiance would cost).
//   ./build/gi/benchmarks/antiradiance_bench --benchmark_counters_tabular=true
#include <GL/glcorearb.h>
#include <benchmark/benchmark.h>
#include <engine/gltf.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_solver.h"
#include "bench_gl.h"
#include "light_atlas/light_atlas.h"

namespace {

glm::mat4 door(float degrees) {
  return glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(6.0f, 0.0f, 5.4f)), glm::radians(degrees),
                     glm::vec3(0.0f, 1.0f, 0.0f));
}

struct Corridor {
  gi::BakeInput input;
  std::uint32_t door_instance = 0;
  std::unique_ptr<gi::AntiradianceRegion> region;
  Corridor() {
    auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/corridor.gltf");
    if (!asset) std::exit(1);
    input = gi::bake_input_from(*asset);
    for (std::size_t i = 0; i < input.instances.size(); ++i)
      if (input.instances[i].deforming) door_instance = static_cast<std::uint32_t>(i);
    gi::AntiradianceSettings s;
    s.patch_size_m = 0.8f;
    region = std::make_unique<gi::AntiradianceRegion>(gi::AntiradianceRegion::create(input, s).value());
  }
};

Corridor& corridor() {
  static Corridor c;
  return c;
}

// Relink of the door's elements + direct light at all elements (the CPU part of a move).
void BM_AntiradianceMoveCpu(benchmark::State& state) {
  Corridor& c = corridor();
  float angle = 50.0f;
  for (auto _ : state) {
    angle = angle > 100.0f ? 10.0f : angle + 7.0f;
    c.region->set_instance_transform(c.door_instance, door(angle));
    c.region->update(false);
  }
  state.counters["relinked"] = static_cast<double>(c.region->counters().relinked_elements);
  state.counters["links"] = static_cast<double>(c.region->counters().links);
}
BENCHMARK(BM_AntiradianceMoveCpu)->Unit(benchmark::kMillisecond)->Iterations(5);

// One iteration (global, push, local, pull) on the GPU, and the CPU twin's.
void BM_AntiradianceIterationGpu(benchmark::State& state) {
  (void)bench::gl_context();
  Corridor& c = corridor();
  auto gpu = gi::AntiradianceGpuPass::create(c.region->hierarchy(), c.region->bins(), c.region->links()).value();
  gpu.reset(c.region->direct());
  for (auto _ : state) {
    gpu.global();
    gpu.push();
    gpu.local(true, true);
    gpu.pull();
    glFinish();
  }
  state.counters["link_records"] = static_cast<double>(c.region->links().links.size());
  state.counters["leaves"] = static_cast<double>(c.region->hierarchy().leaf_count());
}
BENCHMARK(BM_AntiradianceIterationGpu)->Unit(benchmark::kMillisecond)->Iterations(5);

// The four GPU passes one by one (arg: 0 global, 1 push, 2 local, 3 pull).
void BM_AntiradiancePassGpu(benchmark::State& state) {
  (void)bench::gl_context();
  Corridor& c = corridor();
  auto gpu = gi::AntiradianceGpuPass::create(c.region->hierarchy(), c.region->bins(), c.region->links()).value();
  gpu.reset(c.region->direct());
  for (auto _ : state) {
    switch (state.range(0)) {
      case 0:
        gpu.global();
        break;
      case 1:
        gpu.push();
        break;
      case 2:
        gpu.local(true, true);
        break;
      default:
        gpu.pull();
        break;
    }
    glFinish();
  }
}
BENCHMARK(BM_AntiradiancePassGpu)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_AntiradianceIterationCpu(benchmark::State& state) {
  Corridor& c = corridor();
  gi::CpuAntiradiancePasses cpu(c.region->hierarchy(), c.region->bins(), c.region->links());
  cpu.reset(c.region->direct());
  for (auto _ : state) {
    cpu.global();
    cpu.push();
    cpu.local(true, true);
    cpu.pull();
  }
}
BENCHMARK(BM_AntiradianceIterationCpu)->Unit(benchmark::kMillisecond)->Iterations(5);

// A whole frame where the door moved, as the runtime runs it (AntiradianceLighting::update):
// relink + direct light on the CPU, link upload, the iteration on the GPU (the settings'
// iterations), the result read back. Arg: iterations.
void BM_AntiradianceDoorMoveGpu(benchmark::State& state) {
  (void)bench::gl_context();
  Corridor& c = corridor();
  gi::AntiradianceSettings s = c.region->settings();
  s.iterations = static_cast<int>(state.range(0));
  auto gpu = gi::AntiradianceGpuPass::create(c.region->hierarchy(), c.region->bins(), c.region->links()).value();
  float angle = 50.0f;
  for (auto _ : state) {
    angle = angle > 100.0f ? 10.0f : angle + 7.0f;
    c.region->set_instance_transform(c.door_instance, door(angle));
    c.region->update(false);
    (void)gpu.set_links(c.region->links());
    (void)gi::run_antiradiance(gpu, c.region->direct(), s, c.region->hierarchy());
    benchmark::DoNotOptimize(gpu.irradiance());
    glFinish();
  }
}
BENCHMARK(BM_AntiradianceDoorMoveGpu)->Arg(8)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(3);

// The same frame with the CPU twin solving. Arg: iterations.
void BM_AntiradianceDoorMoveCpu(benchmark::State& state) {
  Corridor& c = corridor();
  gi::AntiradianceSettings s = c.region->settings();
  s.iterations = static_cast<int>(state.range(0));
  gi::CpuAntiradiancePasses cpu(c.region->hierarchy(), c.region->bins(), c.region->links());
  float angle = 50.0f;
  for (auto _ : state) {
    angle = angle > 100.0f ? 10.0f : angle + 7.0f;
    c.region->set_instance_transform(c.door_instance, door(angle));
    c.region->update(false);
    (void)gi::run_antiradiance(cpu, c.region->direct(), s, c.region->hierarchy());
    benchmark::DoNotOptimize(cpu.irradiance());
  }
}
BENCHMARK(BM_AntiradianceDoorMoveCpu)->Arg(8)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(3);

const char* preset_name(std::int64_t arg) { return arg == 0 ? "preview" : arg == 1 ? "medium" : "high"; }

// The corridor's light atlas re-baked at `preset` with the door shut (once per preset and
// process, ms): the yardstick of a door move.
double atlas_rebake_ms(const char* preset) {
  static std::map<std::string, double> measured;
  if (auto it = measured.find(preset); it != measured.end()) return it->second;
  Corridor& c = corridor();
  gi::BakeInput shut = c.input;
  shut.instances[c.door_instance].object_to_world = door(0.0f);
  auto settings = gi::light_atlas_preset(preset);
  if (!settings) std::exit(1);
  const auto t0 = std::chrono::steady_clock::now();
  auto atlas = gi::bake_light_atlas(shut, *settings);
  if (!atlas) {
    std::fprintf(stderr, "%s\n", atlas.error().to_string().c_str());
    std::exit(1);
  }
  benchmark::DoNotOptimize(atlas->irradiance.data());
  return measured[preset] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// One door move at a gi-bake preset (arg: 0 preview, 1 medium, 2 high; gi::antiradiance_preset):
// the region made from the preset's bake as a load makes it, then per iteration the door to
// the next of 0 / 25 / 100 degrees, relink + direct light + the solve to its tolerance on
// the CPU twin (the sweep's cpu move + solve). Counters: door_move_ms (mean), atlas_rebake_ms,
// vs_rebake = atlas_rebake_ms / door_move_ms, iterations (mean), links, leaves.
void BM_DoorMoveAtPreset(benchmark::State& state) {
  Corridor& c = corridor();
  const char* preset = preset_name(state.range(0));
  const double rebake_ms = atlas_rebake_ms(preset);
  gi::AntiradianceSettings s = gi::antiradiance_preset(preset);
  auto bake = gi::bake_antiradiance(c.input, s);
  if (!bake) std::exit(1);
  auto region = gi::AntiradianceRegion::create(c.input, std::move(bake).value());
  if (!region) std::exit(1);
  region->update();  // the baked pose's solve, as the first frame after a load
  constexpr float kAngles[] = {0.0f, 25.0f, 100.0f};
  std::size_t k = 0;
  double total_ms = 0.0, iterations = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    region->set_instance_transform(c.door_instance, door(kAngles[k++ % std::size(kAngles)]));
    const gi::AntiradianceSolveReport rep = region->update();
    benchmark::DoNotOptimize(region->irradiance().data());
    total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    iterations += rep.iterations;
  }
  const double moves = static_cast<double>(state.iterations());
  state.counters["door_move_ms"] = total_ms / moves;
  state.counters["atlas_rebake_ms"] = rebake_ms;
  state.counters["vs_rebake"] = rebake_ms / (total_ms / moves);
  state.counters["iterations"] = iterations / moves;
  state.counters["links"] = static_cast<double>(region->links().links.size());
  state.counters["leaves"] = static_cast<double>(region->hierarchy().leaf_count());
  state.counters["bins"] = static_cast<double>(region->bins().count());
}
BENCHMARK(BM_DoorMoveAtPreset)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(3);

// The yardstick for ratios on shared cores: sorting 1.6 M random 16-byte records by
// (receiver, bin, sender) -- the job a relink did in full before it merged (a fixed
// amount of memory-bound CPU work, unaffected by the method's code).
void BM_Yardstick(benchmark::State& state) {
  std::vector<gi::Link> base(1'600'000);
  std::uint64_t x = 12345;
  for (gi::Link& l : base) {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    l = {static_cast<std::int32_t>(x >> 40) % 5000, static_cast<std::int32_t>(x >> 20) % 5000,
         static_cast<std::int32_t>(x >> 10) % 64, 1.0f};
  }
  for (auto _ : state) {
    std::vector<gi::Link> v = base;
    std::sort(v.begin(), v.end(), [](const gi::Link& a, const gi::Link& b) {
      if (a.receiver != b.receiver) return a.receiver < b.receiver;
      return a.bin != b.bin ? a.bin < b.bin : a.sender < b.sender;
    });
    benchmark::DoNotOptimize(v.data());
  }
}
BENCHMARK(BM_Yardstick)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
