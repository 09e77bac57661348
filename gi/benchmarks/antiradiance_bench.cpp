// Per-frame cost of the antiradiance region of assets/corridor.gltf (the door) at the
// preview bake settings (0.8 m elements, 64 bins): what a frame where the door moved costs,
// phase by phase. llvmpipe timings are CPU timings (DESIGN.md §4); GPU phases end in glFinish.
// BM_DoorMoveAtPreset (issue 37): one door move at a gi-bake preset's settings, from the bake
// as a load gets it, against re-baking the corridor's light atlas at the same preset in the
// same run (what a door without antiradiance would cost). BM_NearVisibilityMoveAtMedium: the
// same with explicit visibility near the door (NearDoorVisibility).
//   ./build/gi/benchmarks/antiradiance_bench --benchmark_counters_tabular=true
#include <GL/glcorearb.h>
#include <benchmark/benchmark.h>
#include <engine/gltf.h>

#include <glm/gtc/matrix_transform.hpp>

#include <time.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_solver.h"
#include "antiradiance/near_door_visibility.h"
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

// CPU time of the whole process (every thread), ms.
double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// The door's angle at move k (from the baked 50 degrees): jumps to 0 / 25 / 100 in turn, or
// steps of 5 degrees between 0 and 100 and back, as a player opens and shuts a door (55, 60,
// ..., 100, 95, ..., 0, 5, ...).
float door_angle(bool small_steps, std::size_t k) {
  constexpr float kJumps[] = {0.0f, 25.0f, 100.0f};
  if (!small_steps) return kJumps[k % std::size(kJumps)];
  const std::size_t phase = (10 + 1 + k) % 40;  // 50 degrees = 10 steps into a 40-step cycle
  return 5.0f * static_cast<float>(phase <= 20 ? phase : 40 - phase);
}

// Door moves at a gi-bake preset, `small_steps` or not (door_angle). Args: preset (0 preview,
// 1 medium, 2 high; gi::antiradiance_preset), warm (0: every solve from the direct light, as
// before the warm start; 1: from the previous pose's solution), threads1 (0: TBB's default,
// the machine's 2; 1: one thread for the passes and the direct light). The region is made
// from the preset's bake as a load makes it and solved at the baked pose (a load's first
// frame); per iteration the door moves, relink + direct light + the solve to its tolerance
// on the CPU twin (the sweep's cpu move + solve). Counters: door_move_ms (wall, mean),
// door_move_cpu_ms (every thread's CPU), relink_direct_cpu_ms (its relink + direct light
// part), links_made (by the relink), max_move_ms, atlas_rebake_ms (the yardstick:
// re-baking the corridor's light atlas at the same preset, door shut, once per process),
// vs_rebake, iterations (mean), links, leaves.
void door_moves(benchmark::State& state, bool small_steps) {
  Corridor& c = corridor();
  const char* preset = preset_name(state.range(0));
  const double rebake_ms = atlas_rebake_ms(preset);
  gi::AntiradianceSettings s = gi::antiradiance_preset(preset);
  s.warm_start = state.range(1) != 0;
  const auto threads = static_cast<std::size_t>(state.range(2) == 1 ? 1 : oneapi::tbb::info::default_concurrency());
  oneapi::tbb::global_control limit(oneapi::tbb::global_control::max_allowed_parallelism, threads);
  auto bake = gi::bake_antiradiance(c.input, s);
  if (!bake) std::exit(1);
  auto region = gi::AntiradianceRegion::create(c.input, std::move(bake).value());
  if (!region) std::exit(1);
  region->update();  // the baked pose's solve, as the first frame after a load
  std::size_t k = 0;
  double total_ms = 0.0, cpu_ms = 0.0, max_ms = 0.0, iterations = 0.0, move_cpu_ms = 0.0, links_made = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_ms();
    region->set_instance_transform(c.door_instance, door(door_angle(small_steps, k++)));
    region->update(false);  // relink + direct light
    move_cpu_ms += process_cpu_ms() - c0;
    links_made += static_cast<double>(region->counters().links_made);
    const gi::AntiradianceSolveReport rep = region->update();  // nothing moved since: the solve
    benchmark::DoNotOptimize(region->irradiance().data());
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    cpu_ms += process_cpu_ms() - c0;
    total_ms += ms;
    max_ms = std::max(max_ms, ms);
    iterations += rep.iterations;
  }
  const double moves = static_cast<double>(state.iterations());
  state.counters["door_move_ms"] = total_ms / moves;
  state.counters["door_move_cpu_ms"] = cpu_ms / moves;
  state.counters["relink_direct_cpu_ms"] = move_cpu_ms / moves;
  state.counters["links_made"] = links_made / moves;
  state.counters["max_move_ms"] = max_ms;
  state.counters["atlas_rebake_ms"] = rebake_ms;
  state.counters["vs_rebake"] = rebake_ms / (total_ms / moves);
  state.counters["iterations"] = iterations / moves;
  state.counters["threads"] = static_cast<double>(threads);
  state.counters["links"] = static_cast<double>(region->links().links.size());
  state.counters["leaves"] = static_cast<double>(region->hierarchy().leaf_count());
  state.counters["bins"] = static_cast<double>(region->bins().count());
}

// The door to 0 / 25 / 100 degrees in turn (3 moves, each angle once).
void BM_DoorMoveAtPreset(benchmark::State& state) { door_moves(state, false); }
BENCHMARK(BM_DoorMoveAtPreset)
    ->ArgNames({"preset", "warm", "threads1"})
    ->Args({0, 0, 1})
    ->Args({0, 0, 0})
    ->Args({0, 1, 0})
    ->Args({1, 0, 1})
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({2, 0, 0})
    ->Args({2, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// The door opened from its baked 50 to 100 degrees, shut to 0 and opened to 50 again in
// 5-degree steps (40 moves: a player at the door, a few degrees per frame; the last move is
// back at the baked pose, where the change is 0 without a solve).
void BM_DoorStepsAtPreset(benchmark::State& state) { door_moves(state, true); }
BENCHMARK(BM_DoorStepsAtPreset)
    ->ArgNames({"preset", "warm", "threads1"})
    ->Args({0, 0, 0})
    ->Args({0, 1, 0})
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({2, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(40);

// Door moves at the medium preset with explicit visibility near the door (issue 37,
// NearDoorVisibility: the leaves within 1 m of the door's reach gather with ray-traced
// visibility). Args: point_pairs per leaf pair, reuse (1: the visibility kept, only the
// segments meeting the door's boxes traced), warm (1: the near solve starts from the last
// pose's), fast (0: one ray at a time, 1: rays in streams of 256, 2: and the kept samples
// tested against the door alone), budget (0: the 1 m radius alone, 1: the preset's budget,
// which on the corridor takes every leaf). Per iteration the door jumps to 0 / 25 / 100
// degrees: the antiradiance move and solve (as BM_DoorMoveAtPreset), then the near leaves'
// update and solve. Counters: door_move_ms (both, wall), antiradiance_ms, near_ms,
// near_update_ms (of near_ms: the couplings), near_iterations, rays, pairs (per move), door_rays
// (of rays: the door's own pairs'), door_only_rays (against the door alone, not in rays), trace_cpu_ms (the
// update's time in Embree, every thread's), near_bake_ms (the
// baked pose's couplings, once), atlas_rebake_ms (the yardstick), vs_rebake.
void BM_NearVisibilityMoveAtMedium(benchmark::State& state) {
  Corridor& c = corridor();
  const double rebake_ms = atlas_rebake_ms("medium");
  const gi::AntiradianceSettings s = gi::antiradiance_preset("medium");
  auto bake = gi::bake_antiradiance(c.input, s);
  if (!bake) std::exit(1);
  auto region = gi::AntiradianceRegion::create(c.input, std::move(bake).value());
  if (!region) std::exit(1);
  const auto tb = std::chrono::steady_clock::now();
  region->update(false);
  gi::NearDoorVisibilitySettings ns = gi::near_door_settings(s);
  if (state.range(4) == 0) ns.budget_bytes = 0;
  ns.point_pairs = static_cast<int>(state.range(0));
  ns.reuse_visibility = state.range(1) != 0;
  ns.warm_start = state.range(2) != 0;
  ns.streams = state.range(3) >= 1;
  ns.door_only_rays = state.range(3) >= 2;
  auto near = gi::NearDoorVisibility::create(c.input, *region, c.door_instance, ns);
  if (!near) std::exit(1);
  const double near_bake_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tb).count();
  region->update();
  std::size_t k = 0;
  double total_ms = 0.0, ar_ms = 0.0, near_ms = 0.0, update_ms = 0.0, rays = 0.0, pairs = 0.0, iterations = 0.0;
  double moving_rays = 0.0, trace_cpu_ms = 0.0, door_only_rays = 0.0;
  for (auto _ : state) {
    const glm::mat4 m = door(door_angle(false, k++));
    const auto t0 = std::chrono::steady_clock::now();
    region->set_instance_transform(c.door_instance, m);
    region->update(false);
    region->update();
    const auto t1 = std::chrono::steady_clock::now();
    const std::vector<glm::vec3> e = near->move(*region, c.door_instance, m);
    benchmark::DoNotOptimize(e.data());
    const auto t2 = std::chrono::steady_clock::now();
    ar_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
    near_ms += std::chrono::duration<double, std::milli>(t2 - t1).count();
    total_ms += std::chrono::duration<double, std::milli>(t2 - t0).count();
    update_ms += near->last_update_ms();
    iterations += static_cast<double>(near->last_iterations());
    rays += static_cast<double>(near->last_rays());
    pairs += static_cast<double>(near->last_pairs());
    moving_rays += static_cast<double>(near->last_moving_rays());
    trace_cpu_ms += near->last_trace_cpu_ms();
    door_only_rays += static_cast<double>(near->last_door_only_rays());
  }
  const double moves = static_cast<double>(state.iterations());
  state.counters["door_move_ms"] = total_ms / moves;
  state.counters["antiradiance_ms"] = ar_ms / moves;
  state.counters["near_ms"] = near_ms / moves;
  state.counters["near_update_ms"] = update_ms / moves;
  state.counters["rays"] = rays / moves;
  state.counters["pairs"] = pairs / moves;
  state.counters["door_rays"] = moving_rays / moves;
  state.counters["trace_cpu_ms"] = trace_cpu_ms / moves;
  state.counters["door_only_rays"] = door_only_rays / moves;
  state.counters["receivers"] = static_cast<double>(near->receivers());
  state.counters["near_iterations"] = iterations / moves;
  state.counters["near_bake_ms"] = near_bake_ms;
  state.counters["atlas_rebake_ms"] = rebake_ms;
  state.counters["vs_rebake"] = rebake_ms / (total_ms / moves);
}
BENCHMARK(BM_NearVisibilityMoveAtMedium)
    ->ArgNames({"pairs", "reuse", "warm", "fast", "budget"})
    ->Args({16, 0, 0, 0, 0})
    ->Args({16, 1, 0, 0, 0})
    ->Args({16, 1, 1, 0, 0})
    ->Args({8, 1, 1, 0, 0})
    ->Args({4, 1, 0, 0, 0})
    ->Args({4, 1, 1, 0, 0})
    ->Args({4, 1, 1, 1, 0})
    ->Args({16, 1, 1, 2, 0})
    ->Args({4, 1, 1, 2, 0})
    ->Args({4, 1, 1, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

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
