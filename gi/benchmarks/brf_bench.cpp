// Basis radiance fields: milliseconds per update for 1, 5, 10 and 30 crates (pairs grow as
// n^2) with the I_c pair culling (§5.4) on and off, and the precomputed memory per object.
// Crates share one mesh, basis and field (instanced props).
//   BM_BrfUpdate: the CPU runtime, direct light included (update_brf);
//   BM_BrfInterreflectCpu: the CPU interreflection alone (brf_interreflect), the GPU pass's twin;
//   BM_BrfInterreflectCpuGlossy: the same with every crate a glossy metal (4 terms asked,
//   GGX alpha 0.25): K = 1 + terms channels per basis function and K rows per receiver;
//   BM_BrfGpu: BrfGpuPass::run on llvmpipe (DESIGN.md §4: these are CPU timings; compare
//   them as ratios), glFinish inside the timed region, with every crate moving each run (all
//   pairs' Phi re-evaluated) or none moving (every Phi reused; only the bounces run);
//   BM_BrfGpuGlossy: the GPU pass with every crate a glossy metal, all moving;
//   BM_BrfGpuOcclusion: the GPU pass with occlusion between the crates off and on;
//   BM_BrfGpuInfluence: the GPU pass, every crate moving, the runtime's default culling,
//   with the influence limit (BrfUpdateSettings::influence_scale) off and on, 10 to 100
//   crates: the pairs evaluated and the time against the crate count;
//   BM_BrfGatherCpu: the CPU twin's bounce loop (brf_gather over every pair's Phi) against
//   a memcpy of the same bytes, interleaved in one loop (vs_memcpy: its share of the host's
//   memory bandwidth).
//   ./build/benchmarks/brf_bench --benchmark_counters_tabular=true
#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <vector>

#include <benchmark/benchmark.h>
#include <engine/gpu/context.h>

#include <glm/gtc/matrix_transform.hpp>
#include "bench_gl.h"

#include <engine/gltf.h>
#include <gi/bake_input.h>

#include "brf/brf_bake.h"
#include "brf/brf_gpu_pass.h"
#include "brf/brf_mesh.h"
#include "brf/brf_runtime.h"

namespace {

gi::BrfMesh crate(float half, int n) { return gi::brf_box_mesh(glm::vec3(half), n); }

struct Shared {
  gi::BrfMesh mesh = crate(0.25f, 4);
  gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = 16}).value();
  gi::BasisRadianceField field = gi::compute_basis_radiance_field(mesh, basis, {}).value();
};

const Shared& shared() {
  static const Shared s;
  return s;
}

// Crates on a floor-like grid, 1.2 m apart: far pairs exchange little light. `turn` rotates
// every crate about its own vertical axis by a per-crate angle (so relative poses change).
std::vector<gi::BrfObject> crates(int n, float turn = 0.0f) {
  const Shared& s = shared();
  std::vector<gi::BrfObject> objects;
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  for (int i = 0; i < n; ++i)
    objects.push_back({&s.mesh, &s.basis, &s.field,
                       glm::rotate(glm::translate(glm::mat4(1.0f), {1.2f * static_cast<float>(i % side), 0.25f,
                                                                    1.2f * static_cast<float>(i / side)}),
                                   turn * static_cast<float>(i + 1), glm::vec3(0.0f, 1.0f, 0.0f)),
                       glm::vec3(0.8f, 0.3f + 0.05f * static_cast<float>(i % 5), 0.2f)});
  return objects;
}

// CPU time of the whole process (every thread: llvmpipe's JIT workers included), ms. On a
// shared machine the wall time moves with the load; this moves much less.
double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

gi::PointEmitter grid_light(int n) {
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  gi::PointEmitter light;
  light.position = {0.5f * static_cast<float>(side), 3.0f, 0.5f * static_cast<float>(side)};
  light.radiant = glm::vec3(20.0f);
  return light;
}

void BM_BrfUpdate(benchmark::State& state) {
  const Shared& s = shared();
  const int n = static_cast<int>(state.range(0));
  const bool cull = state.range(1) != 0;
  const std::vector<gi::BrfObject> objects = crates(n);
  const gi::PointEmitter light = grid_light(n);
  std::size_t evaluated = 0, culled = 0;
  for (auto _ : state) {
    const gi::BrfResult r = gi::update_brf(objects, std::span<const gi::PointEmitter>(&light, 1),
                                           {.bounces = 3, .cull_threshold = cull ? 1e-2f : 0.0f});
    evaluated = r.pairs_evaluated;
    culled = r.pairs_culled;
    benchmark::DoNotOptimize(r.indirect.data());
  }
  state.counters["pairs_evaluated"] = static_cast<double>(evaluated);
  state.counters["pairs_culled"] = static_cast<double>(culled);
  state.counters["field_MB_per_mesh"] = static_cast<double>(s.field.bytes()) / 1e6;
  state.counters["basis_MB_per_mesh"] = static_cast<double>(s.basis.psi.size() * sizeof(float)) / 1e6;
}
BENCHMARK(BM_BrfUpdate)->ArgsProduct({{1, 5, 10, 30}, {0, 1}})->Unit(benchmark::kMillisecond);

void BM_BrfInterreflectCpu(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const bool cull = state.range(1) != 0;
  const std::vector<gi::BrfObject> objects = crates(n);
  const gi::PointEmitter light = grid_light(n);
  const auto incoming = gi::brf_direct_light(objects, std::span<const gi::PointEmitter>(&light, 1), nullptr);
  for (auto _ : state) {
    const gi::BrfResult r =
        gi::brf_interreflect(objects, incoming, {.bounces = 3, .cull_threshold = cull ? 1e-2f : 0.0f});
    benchmark::DoNotOptimize(r.indirect.data());
  }
}
BENCHMARK(BM_BrfInterreflectCpu)->ArgsProduct({{1, 5, 10, 30}, {0, 1}})->Unit(benchmark::kMillisecond);

struct SharedGlossy {
  gi::BrfMesh mesh = crate(0.25f, 4);
  gi::BrdfSeparation sep =
      gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.25f}, {.terms = 4, .resolution = 16}).value();
  gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = 16}, &sep).value();
  gi::BasisRadianceField field = gi::compute_basis_radiance_field(mesh, basis, {}, &sep).value();
};

void BM_BrfInterreflectCpuGlossy(benchmark::State& state) {
  static const SharedGlossy g;
  const int n = static_cast<int>(state.range(0));
  std::vector<gi::BrfObject> objects = crates(n);
  for (gi::BrfObject& o : objects) {
    o.basis = &g.basis;
    o.field = &g.field;
    o.glossy = &g.sep;
    o.albedo = glm::vec3(0.0f);
  }
  const gi::PointEmitter light = grid_light(n);
  const auto incoming = gi::brf_direct_light(objects, std::span<const gi::PointEmitter>(&light, 1), nullptr);
  for (auto _ : state) {
    const gi::BrfResult r = gi::brf_interreflect(objects, incoming, {.bounces = 3, .cull_threshold = 0.0f});
    benchmark::DoNotOptimize(r.indirect.data());
  }
  state.counters["terms"] = static_cast<double>(g.field.terms);
  state.counters["field_MB_per_mesh"] = static_cast<double>(g.field.bytes()) / 1e6;
}
BENCHMARK(BM_BrfInterreflectCpuGlossy)->Arg(1)->Arg(5)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);

// The GPU pass over n crates, timed per run() with glFinish: moving alternates two poses a few
// degrees apart (every Phi re-evaluated), still repeats one (every Phi reused). Counters: the
// process's CPU ms per run (llvmpipe's threads included) and the pass's stats.
void run_gpu_pass(benchmark::State& state, int n, bool moving, const gi::BrfUpdateSettings& settings) {
  (void)bench::gl_context();
  const Shared& s = shared();
  const gi::BrfModel model{"", s.mesh, s.basis, s.field};
  auto pass = gi::BrfGpuPass::create(std::span(&model, 1));
  if (!pass) {
    state.SkipWithError(pass.error().to_string().c_str());
    return;
  }
  const gi::PointEmitter light = grid_light(n);
  std::vector<gi::BrfInstance> poses[2];
  for (int k = 0; k < 2; ++k)
    for (const gi::BrfObject& o : crates(n, 0.02f * static_cast<float>(k)))
      poses[k].push_back({0, o.object_to_world, o.albedo});
  const auto incoming = gi::brf_direct_light(crates(n), std::span<const gi::PointEmitter>(&light, 1), nullptr);
  if (!pass->run(poses[1], incoming, settings)) state.SkipWithError("run failed");
  glFinish();
  std::size_t frame = 0;
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    const auto status = pass->run(poses[moving ? frame % 2 : 1], incoming, settings);
    glFinish();
    if (!status) state.SkipWithError(status.error().to_string().c_str());
    ++frame;
  }
  state.counters["process_cpu_ms"] = (process_cpu_ms() - cpu0) / static_cast<double>(std::max<std::size_t>(frame, 1));
  state.counters["pairs_evaluated"] = static_cast<double>(pass->stats().pairs_evaluated);
  state.counters["pairs_reused"] = static_cast<double>(pass->stats().pairs_reused);
  state.counters["pairs_lod"] = static_cast<double>(pass->stats().pairs_lod);
  state.counters["lod_points_packed"] = static_cast<double>(pass->stats().lod_points_packed);
  state.counters["run_cpu_ms"] = pass->stats().cpu_ms;
  state.counters["gpu_MB"] = static_cast<double>(pass->gpu_bytes()) / 1e6;
}

// n crates, moving or still, bound culling on or off; the default settings otherwise (the
// level of detail included).
void BM_BrfGpu(benchmark::State& state) {
  run_gpu_pass(state, static_cast<int>(state.range(0)), state.range(1) != 0,
               {.bounces = 3, .cull_threshold = state.range(2) != 0 ? 1e-2f : 0.0f});
}
BENCHMARK(BM_BrfGpu)->ArgsProduct({{1, 5, 10, 30}, {0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);

// The level of detail for distant pairs (BrfUpdateSettings::lod_distance, brf_lod.h): every
// crate moving, no bound culling, as BM_BrfGpu/n/1/0 with lod_distance = the second arg / 10
// (0: off, the exact evaluation); third arg 1: shared visibility (lod_shared_visibility).
// Counter pairs_lod: the far pairs interpolated.
void BM_BrfGpuLod(benchmark::State& state) {
  run_gpu_pass(state, static_cast<int>(state.range(0)), true,
               {.bounces = 3,
                .cull_threshold = 0.0f,
                .lod_distance = static_cast<float>(state.range(1)) / 10.0f,
                .lod_shared_visibility = state.range(2) != 0});
}
BENCHMARK(BM_BrfGpuLod)->ArgsProduct({{30}, {0, 20, 30, 50}, {0, 1}})->Unit(benchmark::kMillisecond);

// The level of detail's error, per vertex, against the exact evaluation (the CPU twin, 3
// bounces, no bound culling, occlusion on): scene 0 the 30 crates of BM_BrfGpuLod (lit by
// grid_light), scene 1 the crates room's dynamic objects (assets/crates_room.gltf, BRF baked at
// the preview preset, a point light 1.5 m above their centre); lod_distance = the second arg /
// 10. Counters: max_rel and p95_rel, the largest and 95th-percentile relative error of a
// vertex's interreflected irradiance (|E_lod - E| / max(|E|, 1% of the mean |E|), RGB
// lengths), pairs_lod of pairs_evaluated; the time is the CPU twin with the level of detail.
// Third arg 1: shared visibility.
struct RoomObjects {
  std::vector<gi::BrfMeshBake> bakes;
  std::vector<gi::BrfSource> sources;
  std::vector<gi::BrfObject> objects;
};

const RoomObjects& crates_room() {
  static const RoomObjects room = [] {
    RoomObjects r;
    auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf");
    if (!asset) return r;
    const engine::Scene scene = engine::instantiate(std::move(asset).value());
    const gi::BakeInput input = gi::bake_input_from(scene);
    auto sources = gi::dynamic_brf_meshes(input);
    if (!sources) return r;
    r.sources = std::move(sources).value();
    const gi::BrfSettings settings = gi::brf_preset("preview").value();
    for (const gi::BrfSource& src : r.sources) r.bakes.push_back(gi::bake_brf_mesh(src, settings).value());
    for (std::size_t m = 0; m < r.sources.size(); ++m)
      for (std::uint32_t i : r.sources[m].instances)
        r.objects.push_back({&r.sources[m].mesh, &r.bakes[m].model.basis, &r.bakes[m].model.field,
                             input.instances[i].object_to_world, gi::brf_source_albedo(input, r.sources[m]),
                             r.bakes[m].model.glossy ? &*r.bakes[m].model.glossy : nullptr, r.sources[m].specular});
    return r;
  }();
  return room;
}

void BM_BrfLodError(benchmark::State& state) {
  const bool room = state.range(0) != 0;
  const float lod = static_cast<float>(state.range(1)) / 10.0f;
  const bool shared = state.range(2) != 0;
  std::vector<gi::BrfObject> objects;
  gi::PointEmitter light = grid_light(30);
  if (room) {
    objects = crates_room().objects;
    if (objects.empty()) {
      state.SkipWithError("crates room: no dynamic objects loaded");
      return;
    }
    glm::vec3 centre(0.0f);
    for (const gi::BrfObject& o : objects) centre += glm::vec3(o.object_to_world[3]);
    light.position = centre / static_cast<float>(objects.size()) + glm::vec3(0.0f, 1.5f, 0.0f);
    light.radiant = glm::vec3(10.0f);
  } else {
    objects = crates(30);
  }
  const auto incoming = gi::brf_direct_light(objects, std::span<const gi::PointEmitter>(&light, 1), nullptr);
  const gi::BrfResult exact =
      gi::brf_interreflect(objects, incoming, {.bounces = 3, .cull_threshold = 0.0f, .lod_distance = 0.0f});
  gi::BrfResult r;
  for (auto _ : state) {
    r = gi::brf_interreflect(
        objects, incoming,
        {.bounces = 3, .cull_threshold = 0.0f, .lod_distance = lod, .lod_shared_visibility = shared});
    benchmark::DoNotOptimize(r.indirect.data());
  }
  const auto [max_rel, p95] = gi::brf_vertex_error(r, exact);
  state.counters["max_rel"] = max_rel;
  state.counters["p95_rel"] = p95;
  state.counters["pairs_lod"] = static_cast<double>(r.pairs_lod);
  state.counters["pairs_evaluated"] = static_cast<double>(r.pairs_evaluated);
}
BENCHMARK(BM_BrfLodError)->ArgsProduct({{0, 1}, {0, 20, 30, 50}, {0, 1}})->Unit(benchmark::kMillisecond);

// Occlusion between the crates (BrfUpdateSettings::occlusion, brf_visibility.h) on and off in
// the same run: crates, moving, occlusion; no culling. On, a pair's Phi also depends on the
// poses of the crates in its way (brf_pair_occluders) and each of its vertices tests 9 lines
// of sight against their boxes.
void BM_BrfGpuOcclusion(benchmark::State& state) {
  (void)bench::gl_context();
  const Shared& s = shared();
  const int n = static_cast<int>(state.range(0));
  const bool moving = state.range(1) != 0;
  const gi::BrfModel model{"", s.mesh, s.basis, s.field};
  auto pass = gi::BrfGpuPass::create(std::span(&model, 1));
  if (!pass) {
    state.SkipWithError(pass.error().to_string().c_str());
    return;
  }
  const gi::PointEmitter light = grid_light(n);
  std::vector<gi::BrfInstance> poses[2];
  for (int k = 0; k < 2; ++k)
    for (const gi::BrfObject& o : crates(n, 0.02f * static_cast<float>(k)))
      poses[k].push_back({0, o.object_to_world, o.albedo});
  const auto incoming = gi::brf_direct_light(crates(n), std::span<const gi::PointEmitter>(&light, 1), nullptr);
  const gi::BrfUpdateSettings settings{.bounces = 3, .cull_threshold = 0.0f, .occlusion = state.range(2) != 0};
  if (!pass->run(poses[1], incoming, settings)) state.SkipWithError("run failed");
  glFinish();
  std::size_t frame = 0;
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    const auto status = pass->run(poses[moving ? frame % 2 : 1], incoming, settings);
    glFinish();
    if (!status) state.SkipWithError(status.error().to_string().c_str());
    ++frame;
  }
  state.counters["process_cpu_ms"] = (process_cpu_ms() - cpu0) / static_cast<double>(std::max<std::size_t>(frame, 1));
  state.counters["pairs_evaluated"] = static_cast<double>(pass->stats().pairs_evaluated);
  state.counters["pairs_reused"] = static_cast<double>(pass->stats().pairs_reused);
}
BENCHMARK(BM_BrfGpuOcclusion)->ArgsProduct({{10, 30}, {0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);

// Sub-quadratic pairs: all crates moving (relative poses change every run), the runtime's
// default culling (1e-3), influence limit off (0) and on (1: each source's outermost field
// sphere). Args: crates, influence on.
void BM_BrfGpuInfluence(benchmark::State& state) {
  (void)bench::gl_context();
  const Shared& s = shared();
  const int n = static_cast<int>(state.range(0));
  const gi::BrfModel model{"", s.mesh, s.basis, s.field};
  auto pass = gi::BrfGpuPass::create(std::span(&model, 1));
  if (!pass) {
    state.SkipWithError(pass.error().to_string().c_str());
    return;
  }
  const gi::PointEmitter light = grid_light(n);
  std::vector<gi::BrfInstance> poses[2];
  for (int k = 0; k < 2; ++k)
    for (const gi::BrfObject& o : crates(n, 0.02f * static_cast<float>(k)))
      poses[k].push_back({0, o.object_to_world, o.albedo});
  const auto incoming = gi::brf_direct_light(crates(n), std::span<const gi::PointEmitter>(&light, 1), nullptr);
  const gi::BrfUpdateSettings settings{.bounces = 3, .influence_scale = static_cast<float>(state.range(1))};
  if (!pass->run(poses[1], incoming, settings)) state.SkipWithError("run failed");
  glFinish();
  std::size_t frame = 0;
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    const auto status = pass->run(poses[frame % 2], incoming, settings);
    glFinish();
    if (!status) state.SkipWithError(status.error().to_string().c_str());
    ++frame;
  }
  state.counters["process_cpu_ms"] = (process_cpu_ms() - cpu0) / static_cast<double>(std::max<std::size_t>(frame, 1));
  state.counters["pair_slots"] = static_cast<double>(pass->stats().pair_slots);
  state.counters["gpu_MB"] = static_cast<double>(pass->gpu_bytes()) / 1e6;
  state.counters["crates"] = n;
  state.counters["pairs_evaluated"] = static_cast<double>(pass->stats().pairs_evaluated);
  state.counters["pairs_culled"] = static_cast<double>(pass->stats().pairs_culled);
  state.counters["all_pairs"] = n * (n - 1);
}
// 200 crates with the limit only: all 39 800 ordered pairs' Phi would not fit one SSBO.
BENCHMARK(BM_BrfGpuInfluence)->ArgsProduct({{10, 30, 60, 100}, {0, 1}})->Args({200, 1})->Unit(benchmark::kMillisecond);

// The CPU twin's bounce loop: brf_gather over every ordered pair's Phi of 30 crates (Phi
// computed once) and, in the same iteration, a memcpy of the same bytes. Counters: GB/s of
// Phi streamed by each (medians over the iterations) and their ratio.
void BM_BrfGatherCpu(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const int n = static_cast<int>(state.range(0));
  const std::vector<gi::BrfObject> objects = crates(n);
  std::vector<gi::BrfWorldVertices> wv;
  for (const gi::BrfObject& o : objects) wv.push_back(gi::brf_world_vertices(o));
  std::vector<std::vector<float>> phi;
  std::vector<std::size_t> source;
  std::size_t bytes = 0;
  for (int s = 0; s < n; ++s)
    for (int r = 0; r < n; ++r) {
      if (s == r) continue;
      gi::brf_basis_irradiance(objects[static_cast<std::size_t>(s)], wv[static_cast<std::size_t>(r)].positions,
                               wv[static_cast<std::size_t>(r)].normals, phi.emplace_back());
      source.push_back(static_cast<std::size_t>(s));
      bytes += phi.back().size() * sizeof(float);
    }
  std::vector<std::array<std::vector<float>, 3>> w;
  for (const gi::BrfObject& o : objects)
    w.push_back(
        gi::brf_fit_rgb(*o.basis, std::vector<glm::vec3>(o.mesh->positions.size(), glm::vec3(1.0f, 0.5f, 0.2f))));
  const std::size_t channels = static_cast<std::size_t>(shared().field.channel_count());
  std::vector<glm::vec3> out(objects[0].mesh->positions.size());
  std::vector<float> copy(bytes / sizeof(float));
  std::vector<double> gather_s, copy_s;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    for (std::size_t p = 0; p < phi.size(); ++p) gi::brf_gather(phi[p], channels, 1, w[source[p]], out);
    benchmark::DoNotOptimize(out.data());
    const auto t1 = Clock::now();
    std::size_t at = 0;
    for (const std::vector<float>& p : phi) {
      std::memcpy(copy.data() + at, p.data(), p.size() * sizeof(float));
      at += p.size();
    }
    benchmark::DoNotOptimize(copy.data());
    benchmark::ClobberMemory();
    const auto t2 = Clock::now();
    gather_s.push_back(std::chrono::duration<double>(t1 - t0).count());
    copy_s.push_back(std::chrono::duration<double>(t2 - t1).count());
    state.SetIterationTime(gather_s.back());  // the time column: the gather alone
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  state.counters["phi_MB"] = static_cast<double>(bytes) * 1e-6;
  state.counters["gather_GB/s"] = static_cast<double>(bytes) * 1e-9 / median(gather_s);
  state.counters["memcpy_GB/s"] = static_cast<double>(bytes) * 1e-9 / median(copy_s);
  state.counters["vs_memcpy"] = median(copy_s) / median(gather_s);
}
BENCHMARK(BM_BrfGatherCpu)->Arg(30)->Unit(benchmark::kMillisecond)->UseManualTime();

// Every crate a glossy metal (SharedGlossy), every crate moving each run.
void BM_BrfGpuGlossy(benchmark::State& state) {
  (void)bench::gl_context();
  static const SharedGlossy g;
  const int n = static_cast<int>(state.range(0));
  const gi::BrfModel model{"", g.mesh, g.basis, g.field, g.sep};
  auto pass = gi::BrfGpuPass::create(std::span(&model, 1));
  if (!pass) {
    state.SkipWithError(pass.error().to_string().c_str());
    return;
  }
  const gi::PointEmitter light = grid_light(n);
  std::vector<gi::BrfObject> objects = crates(n);
  for (gi::BrfObject& o : objects)
    o.basis = &g.basis, o.field = &g.field, o.glossy = &g.sep, o.albedo = glm::vec3(0.0f);
  std::vector<gi::BrfInstance> poses[2];
  for (int k = 0; k < 2; ++k)
    for (const gi::BrfObject& o : crates(n, 0.02f * static_cast<float>(k)))
      poses[k].push_back({0, o.object_to_world, glm::vec3(0.0f)});
  const auto incoming = gi::brf_direct_light(objects, std::span<const gi::PointEmitter>(&light, 1), nullptr);
  const gi::BrfUpdateSettings settings{.bounces = 3, .cull_threshold = 0.0f};
  if (!pass->run(poses[1], incoming, settings)) state.SkipWithError("run failed");
  glFinish();
  std::size_t frame = 0;
  for (auto _ : state) {
    const auto status = pass->run(poses[frame % 2], incoming, settings);
    glFinish();
    if (!status) state.SkipWithError(status.error().to_string().c_str());
    ++frame;
  }
  state.counters["gpu_MB"] = static_cast<double>(pass->gpu_bytes()) / 1e6;
}
BENCHMARK(BM_BrfGpuGlossy)->Arg(1)->Arg(5)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
