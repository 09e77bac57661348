// One PRM light change on the demo level's preview bake (assets/demo_level.gltf, the PRM and
// light atlas presets gi-bake uses for `--preset preview`), the path PrmLighting::frame()
// takes when one moving light changed: the swinging lamp swung to a new pose, its point
// emitters, entry irradiance (shadow rays against the static world, flux check), cluster
// weights, the K = 32 heaviest clusters, and the GPU pane sum with glFinish.
// The yardstick, measured in the same run: re-baking the light atlas (preview) for the
// change, which is what a light without the PRM would cost. Argument `coarse`: 1 panes at
// half the atlas's density, upsampled (the medium preset's ratio, issue 38), 0 the preview
// preset's panes at the atlas's density, both in the same run; counters gpu_mb
// (PrmGpuPass::gpu_bytes) and upsampler_build_ms (what a load adds to read coarse panes).
//   ./build/gi/benchmarks/prm_relight_bench --benchmark_counters_tabular=true
// Counters (medians over the iterations): cpu_ms (emitters, entry irradiance, weights,
// selection), gpu_ms (pane sum + glFinish; CPU time on llvmpipe), atlas_rebake_ms (one bake
// before the loop), vs_rebake = atlas_rebake_ms / (cpu_ms + gpu_ms) (issue 23 target >= 1000),
// clusters (selected), texels (pane elements), gpu_k0_ms (the pane sum with no cluster after
// one with none: its fixed part, nothing written since the panes are sparse), chunks_per_change
// (blocks of eight slots a change wrote: the picked clusters' tiles and the last change's),
// chunks_all_tiles (every tile's), pane_blocks_stored_share, nonzero_blocks (share of the
// panes' blocks of 8 elements holding any non-zero value), picked_nonzero_blocks (the same
// over the last change's clusters), picked_zero_runs64 (share of those clusters' runs of 64
// elements, one 8-lane SIMD group of 8-element blocks on llvmpipe, that are all zero: all a
// zero-block skip could drop there), unlit_runs64 / unlit_runs512 (share of the runs of 64 /
// 512 elements that no cluster of two consecutive poses' picks lights: what a change could
// leave unwritten, exactly; 0 on the demo level); cpu_cpu_time_ms, gpu_cpu_time_ms,
// gpu_k0_cpu_time_ms: the same parts in process CPU time (all threads, llvmpipe's included),
// steadier than wall time when other jobs share the cores. BM_PrmFluxCheck and
// BM_PrmEntryShadowRays time the CPU part's two ray sets alone.
#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/gtc/matrix_transform.hpp>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake_input.h>

#include "bench_gl.h"

#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
#include "prm/prm_io.h"
#include "prm/prm_runtime.h"
#include "raytrace/scene_adapter.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"

namespace {

using Clock = std::chrono::steady_clock;

template <class T>
T or_exit(engine::Result<T> r) {
  if (!r) {
    std::fprintf(stderr, "%s\n", r.error().to_string().c_str());
    std::exit(1);
  }
  return std::move(r).value();
}

struct DemoLevel {
  gi::BakeInput input;
  gi::Prm prm;        // the preview preset with panes at half the atlas's density, upsampled (medium's ratio)
  gi::Prm dense_prm;  // the preview preset: panes at the atlas's density (pane_texels_per_metre = 0)
  double upsampler_build_ms = 0.0;  // prm_atlas_read (atlas rasterized, taps built): what a load adds
  std::unique_ptr<gi::RayCaster> caster;
  engine::Light lamp;
  glm::mat4 lamp_world{1.0f};
};

const DemoLevel& demo_level() {
  static const DemoLevel d = [] {
    DemoLevel out;
    engine::Scene scene =
        engine::instantiate(or_exit(engine::load_gltf(std::string(GI_SOURCE_DIR) + "/assets/demo_level.gltf")));
    engine::update_world_transforms(scene.registry);
    bool found = false;
    scene.registry.view<engine::Light, engine::WorldTransform>().each(
        [&](engine::Entity, const engine::Light& l, const engine::WorldTransform& wt) {
          if (!l.moves || found) return;
          out.lamp = l;
          out.lamp_world = wt.matrix;
          found = true;
        });
    if (!found) {
      std::fprintf(stderr, "demo_level.gltf has no moving light\n");
      std::exit(1);
    }
    out.input = gi::bake_input_from(scene);
    const gi::PrmSettings preview = or_exit(gi::prm_preset("preview"));
    gi::PrmSettings coarse = preview;
    coarse.pane_texels_per_metre = 0.5f * preview.texels_per_metre;
    out.prm = or_exit(gi::bake_prm(out.input, coarse));
    gi::PrmSettings dense = preview;
    dense.pane_texels_per_metre = 0.0f;
    out.dense_prm = or_exit(gi::bake_prm(out.input, dense));
    if (out.prm.atlas) {
      const auto b0 = Clock::now();
      benchmark::DoNotOptimize(or_exit(gi::prm_atlas_read(out.prm, out.prm.atlas->layout, out.input)));
      out.upsampler_build_ms = std::chrono::duration<double, std::milli>(Clock::now() - b0).count();
    }
    out.caster = or_exit(gi::make_static_caster(out.input));
    return out;
  }();
  return d;
}

// CPU time of the whole process (every thread: llvmpipe's shader threads included), ms.
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Per-texel error of the atlas summed from `test` panes against the one from `ref` panes, over
// the 8 poses' K-sums (sum_panes, the GPU pass's CPU twin): over the lit texels (largest
// channel in `ref` above 1e-6 of the pose's brightest texel: below it half floats flush pane
// values to zero), a texel's error is max over channels |test - ref| / its largest channel.
struct AtlasError {
  double max = 0.0, p95 = 0.0;
  double rel_rmse = 0.0;  // sqrt(sum |test - ref|^2 / sum |ref|^2) over the lit texels and channels
  double total = 0.0;     // |sum test - sum ref| / sum ref (all channels)
};
AtlasError atlas_error(const gi::Prm& test, const gi::Prm& ref,
                       const std::vector<std::vector<gi::ClusterWeight>>& picks) {
  std::vector<double> rel;
  double d2 = 0.0, r2 = 0.0, st = 0.0, sr = 0.0;
  for (const auto& picked : picks) {
    const std::vector<glm::vec3> a = gi::sum_panes(test, picked), b = gi::sum_panes(ref, picked);
    float brightest = 0.0f;
    for (const glm::vec3& v : b) brightest = std::max({brightest, v.x, v.y, v.z});
    for (std::size_t t = 0; t < a.size(); ++t) {
      const float top = std::max({b[t].x, b[t].y, b[t].z});
      if (!(top > 1e-6f * brightest)) continue;
      const glm::vec3 e = glm::abs(a[t] - b[t]);
      rel.push_back(static_cast<double>(std::max({e.x, e.y, e.z}) / top));
      d2 += static_cast<double>(glm::dot(e, e));
      r2 += static_cast<double>(glm::dot(b[t], b[t]));
      st += static_cast<double>(a[t].x + a[t].y + a[t].z);
      sr += static_cast<double>(b[t].x + b[t].y + b[t].z);
    }
  }
  AtlasError out;
  if (rel.empty()) return out;
  std::sort(rel.begin(), rel.end());
  out.max = rel.back();
  out.p95 = rel[rel.size() * 95 / 100];
  out.rel_rmse = std::sqrt(d2 / r2);
  out.total = std::abs(st - sr) / sr;
  return out;
}

gi::Prm with_panes(const gi::Prm& prm, gi::PrmPaneEncoding encoding) {
  gi::Prm out = prm;
  out.panes = or_exit(gi::decoded_panes(prm, encoding));
  return out;
}

// Arguments: the pane encoding (0 half floats, 1 RGB9E5), the threads tracing the flux check
// (1: the calling thread, PrmLighting's default), base (1: the re-baked light atlas set as
// the pass's base, the demo's case) and coarse (1: the preset's panes at half the atlas's
// density, upsampled; 0: dense panes at the atlas's density, as before issue 38's coarse panes). Extra counters: the
// K-sum atlas's error under this encoding against half floats (err_vs_half_*) and against the float panes
// (err_vs_float_*), per texel (max, p95), rel RMSE and total, over the 8 poses.
void BM_PrmLightChange(benchmark::State& state) {
  const DemoLevel& level = demo_level();
  const bool coarse = state.range(3) != 0;
  struct {
    const gi::BakeInput& input;
    const gi::Prm& prm;
    const std::unique_ptr<gi::RayCaster>& caster;
    const engine::Light& lamp;
    const glm::mat4& lamp_world;
  } d{level.input, coarse ? level.prm : level.dense_prm, level.caster, level.lamp, level.lamp_world};
  (void)bench::gl_context();
  const auto encoding = static_cast<gi::PrmPaneEncoding>(state.range(0));
  std::unique_ptr<gi::ThreadPool> pool;
  if (state.range(1) > 1) pool = std::make_unique<gi::ThreadPool>(static_cast<unsigned>(state.range(1)));
  gi::PrmGpuPass pass = or_exit(gi::PrmGpuPass::create(d.prm, {.encoding = encoding}));
  constexpr int kActive = 32;  // GISystemSettings::prm_active_clusters

  // The yardstick: the light atlas re-baked (preview), once, in this run.
  const auto b0 = Clock::now();
  const auto atlas = or_exit(gi::bake_light_atlas(d.input, or_exit(gi::light_atlas_preset("preview"))));
  const double rebake_ms = std::chrono::duration<double, std::milli>(Clock::now() - b0).count();
  benchmark::DoNotOptimize(atlas.irradiance.data());

  // The lamp swung about its pivot (1.35 m above it) through 8 poses, -20 .. +15 degrees.
  const glm::vec3 pivot = glm::vec3(d.lamp_world[3]) + glm::vec3(0.0f, 1.35f, 0.0f);
  std::vector<glm::mat4> poses;
  for (int i = 0; i < 8; ++i) {
    const float angle = glm::radians(-20.0f + 5.0f * static_cast<float>(i));
    poses.push_back(glm::translate(glm::mat4(1.0f), pivot) * glm::rotate(glm::mat4(1.0f), angle, glm::vec3(0, 0, 1)) *
                    glm::translate(glm::mat4(1.0f), -pivot) * d.lamp_world);
  }
  // Argument 3: with the re-baked atlas as the base, as PrmLighting runs on a bundle with a light atlas.
  if (state.range(2) != 0 && !pass.set_base(atlas.irradiance)) state.SkipWithError("PrmGpuPass::set_base failed");
  (void)pass.run({});  // first-dispatch shader compilation in llvmpipe
  glFinish();
  std::vector<double> cpu, gpu, cpu_time, gpu_time, chunks;
  std::size_t frame = 0, clusters = 0;
  std::vector<gi::ClusterWeight> last_picked;
  std::vector<std::vector<gi::ClusterWeight>> picks;  // one per pose
  for (auto _ : state) {
    const double c0 = process_cpu_ms();
    const auto t0 = Clock::now();
    const gi::ReferenceLight ref = gi::reference_light(d.lamp, poses[frame++ % poses.size()]);
    const std::vector<gi::PointEmitter> emitters =
        gi::light_point_emitters(std::span<const gi::ReferenceLight>(&ref, 1), 16, d.prm.settings.seed);
    const std::vector<glm::vec3> entry = gi::entry_irradiance(d.prm, emitters, *d.caster, pool.get());
    const std::vector<gi::ClusterWeight> picked = gi::select_clusters(gi::cluster_weights(d.prm, entry), kActive);
    const auto t1 = Clock::now();
    const double c1 = process_cpu_ms();
    if (!pass.run(picked)) state.SkipWithError("PrmGpuPass::run failed");
    glFinish();
    const auto t2 = Clock::now();
    const double c2 = process_cpu_ms();
    cpu_time.push_back(c1 - c0);
    gpu_time.push_back(c2 - c1);
    cpu.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    gpu.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    clusters = picked.size();
    chunks.push_back(static_cast<double>(pass.last_run_chunks()));
    last_picked = picked;
    if (picks.size() < poses.size()) picks.push_back(picked);
  }
  // The pane sum's fixed part: no cluster selected (the texel list read, every texel written).
  std::vector<double> empty, empty_time;
  for (int i = 0; i < 20; ++i) {
    const double c0 = process_cpu_ms();
    const auto t0 = Clock::now();
    (void)pass.run({});
    glFinish();
    empty.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    empty_time.push_back(process_cpu_ms() - c0);
  }
  state.counters["gpu_k0_ms"] = median(empty);
  // Sparse panes (issue 38): blocks of eight slots one change wrote (the picked clusters'
  // tiles and the last change's), against every tile's, and the share of blocks stored.
  {
    std::size_t all_chunks = 0;
    for (std::size_t k = 0; k < d.prm.panes.tiles.tiles(); ++k) all_chunks += (d.prm.panes.tiles.size(k) + 7) / 8;
    state.counters["chunks_per_change"] = median(chunks);
    state.counters["chunks_all_tiles"] = static_cast<double>(all_chunks);
    state.counters["pane_blocks_stored_share"] =
        static_cast<double>(d.prm.panes.blocks.size()) /
        static_cast<double>(std::max<std::size_t>(1, d.prm.panes.tiles.tiles() * d.prm.panes.cluster_count()));
  }
  state.counters["pane_mb"] = static_cast<double>(pass.pane_bytes()) / 1e6;
  state.counters["gpu_mb"] = static_cast<double>(pass.gpu_bytes()) / 1e6;
  state.counters["upsampler_build_ms"] = coarse ? level.upsampler_build_ms : 0.0;
  {
    const gi::Prm mine = with_panes(d.prm, encoding);
    const gi::Prm half = with_panes(d.prm, gi::PrmPaneEncoding::Half);
    for (const auto& [name, ref] : {std::pair<const char*, const gi::Prm*>{"half", &half}, {"float", &d.prm}}) {
      const AtlasError e = atlas_error(mine, *ref, picks);
      const std::string prefix = std::string("err_vs_") + name;
      state.counters[prefix + "_max"] = e.max;
      state.counters[prefix + "_p95"] = e.p95;
      state.counters[prefix + "_rmse"] = e.rel_rmse;
      state.counters[prefix + "_total"] = e.total;
    }
  }
  state.counters["gpu_k0_cpu_time_ms"] = median(empty_time);
  // Process CPU time (all threads) of each part: steadier than wall time under load.
  state.counters["cpu_cpu_time_ms"] = median(cpu_time);
  state.counters["gpu_cpu_time_ms"] = median(gpu_time);
  const double cpu_ms = median(cpu), gpu_ms = median(gpu);
  state.counters["cpu_ms"] = cpu_ms;
  state.counters["gpu_ms"] = gpu_ms;
  state.counters["total_ms"] = cpu_ms + gpu_ms;
  state.counters["atlas_rebake_ms"] = rebake_ms;
  state.counters["vs_rebake"] = rebake_ms / (cpu_ms + gpu_ms);
  state.counters["clusters"] = static_cast<double>(clusters);
  state.counters["texels"] = static_cast<double>(d.prm.texels.size());
  state.counters["atlas_texels"] = static_cast<double>(d.prm.atlas_width()) * static_cast<double>(d.prm.atlas_height());
  state.counters["entries"] = static_cast<double>(d.prm.entries.size());
  {
    const std::size_t n = d.prm.texels.size();
    const std::vector<float> panes = gi::dense_panes(d.prm);
    std::size_t nonzero = 0, total = 0;
    for (int c = 0; c < d.prm.cluster_count; ++c)
      for (std::size_t first = 0; first < n; first += 8, ++total) {
        bool any = false;
        for (std::size_t i = first; i < std::min(n, first + 8) && !any; ++i)
          for (int ch = 0; ch < 3; ++ch) any |= panes[(std::size_t(c) * n + i) * 3 + ch] != 0.0f;
        nonzero += any;
      }
    state.counters["nonzero_blocks"] = double(nonzero) / double(total);
    // The same share over the clusters the last change summed (what the GPU pass reads).
    std::size_t picked_nonzero = 0, picked_total = 0;
    for (const gi::ClusterWeight& w : last_picked)
      for (std::size_t first = 0; first < n; first += 8, ++picked_total) {
        bool any = false;
        for (std::size_t i = first; i < std::min(n, first + 8) && !any; ++i)
          for (int ch = 0; ch < 3; ++ch) any |= panes[(std::size_t(w.cluster) * n + i) * 3 + ch] != 0.0f;
        picked_nonzero += any;
      }
    // Runs of 8 blocks (64 elements, one 8-lane SIMD group of llvmpipe) all zero: what the skip can drop.
    std::size_t zero_runs = 0, runs = 0;
    for (const gi::ClusterWeight& w : last_picked)
      for (std::size_t first = 0; first < n; first += 64, ++runs) {
        bool any = false;
        for (std::size_t i = first; i < std::min(n, first + 64) && !any; ++i)
          for (int ch = 0; ch < 3; ++ch) any |= panes[(std::size_t(w.cluster) * n + i) * 3 + ch] != 0.0f;
        zero_runs += !any;
      }
    state.counters["picked_zero_runs64"] = runs ? double(zero_runs) / double(runs) : 0.0;
    // Runs of 64 / 512 elements (one SIMD group / one work group) that no cluster of two
    // consecutive poses' picks lights: the texels a change could leave unwritten, exactly.
    for (const std::size_t run : {std::size_t{64}, std::size_t{512}}) {
      std::size_t unchanged = 0, all = 0;
      for (std::size_t p = 1; p < picks.size(); ++p)
        for (std::size_t first = 0; first < n; first += run, ++all) {
          bool any = false;
          for (const auto* picked : {&picks[p - 1], &picks[p]})
            for (const gi::ClusterWeight& w : *picked)
              for (std::size_t i = first; i < std::min(n, first + run) && !any; ++i)
                for (int ch = 0; ch < 3; ++ch) any |= panes[(std::size_t(w.cluster) * n + i) * 3 + ch] != 0.0f;
          unchanged += !any;
        }
      state.counters["unlit_runs" + std::to_string(run)] = all ? double(unchanged) / double(all) : 0.0;
    }
    state.counters["picked_nonzero_blocks"] = picked_total ? double(picked_nonzero) / double(picked_total) : 0.0;
  }
}
BENCHMARK(BM_PrmLightChange)
    ->ArgNames({"rgb9e5", "threads", "base", "coarse"})
    ->Args({0, 1, 0, 1})
    ->Args({1, 1, 0, 1})
    ->Args({1, 2, 0, 1})
    ->Args({1, 1, 1, 1})
    ->Args({1, 1, 0, 0})
    ->Args({1, 1, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// The upsampler's GPU bytes in the format before issue 38's compact reads (8 bytes per fine
// texel and per tap, a ring texel's taps the union of its neighbours'), for the memory table.
std::size_t old_format_upsample_bytes(const gi::PaneUpsampler& up) {
  std::vector<std::vector<std::uint32_t>> taps(up.fine_size());
  std::size_t count = 0;
  const auto coarse_index = [&](int x, int y) { return static_cast<std::uint32_t>(y * up.coarse_width() + x); };
  for (const gi::PaneUpsampler::Read& r : up.reads())
    for (int k = 0; k < 4; ++k)
      if (r.weight[static_cast<std::size_t>(k)] > 0.0f)
        taps[r.fine].push_back(coarse_index(r.origin.x + (k & 1), r.origin.y + (k >> 1)));
  const auto w = static_cast<std::size_t>(up.fine_width());
  for (const gi::PaneUpsampler::RingTexel& r : up.ring_texels()) {
    std::vector<std::uint32_t> merged;
    for (std::size_t k = 0; k < 8; ++k)
      if (r.neighbours & (1u << k)) {
        const std::size_t n = (r.fine / w + static_cast<std::size_t>(gi::PaneUpsampler::kNeighbour[k].y)) * w +
                              r.fine % w + static_cast<std::size_t>(gi::PaneUpsampler::kNeighbour[k].x);
        merged.insert(merged.end(), taps[n].begin(), taps[n].end());
      }
    std::sort(merged.begin(), merged.end());
    merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
    taps[r.fine] = std::move(merged);
  }
  for (const auto& t : taps) count += t.size();
  return (up.reads().size() + up.ring_texels().size() + 1 + count) * 8;
}

// A baked bundle's PRM (issue 38: Dabrovic Sponza with a moving torch at the medium preset),
// when GI_PRM_BENCH_SCENE (the glTF) and GI_PRM_BENCH_BUNDLE (its bundle, baked with
// `gi-bake --methods prm`) are set; skipped otherwise. Loads the PRM as a game does (load_prm:
// the upsampler rebuilt), uploads it as RGB9E5 and reports its memory by part (MB): the GPU
// pass's (PrmGpuPass::memory) and the CPU copy PrmLighting keeps (float panes, upsampler
// taps). Then one light change per iteration, the first moving light carried through 8 poses
// (0.5 m steps along x about its authored place). With GI_PRM_BENCH_REBAKE=<preset>, the
// yardstick: the light atlas of the same scene re-baked once with that light static.
//   GI_PRM_BENCH_SCENE=sponza_torch.gltf GI_PRM_BENCH_BUNDLE=sponza.gibake
//     ./build/gi/benchmarks/prm_relight_bench --benchmark_filter=BM_PrmBundle --benchmark_counters_tabular=true
void BM_PrmBundle(benchmark::State& state) {
  const char* scene_path = std::getenv("GI_PRM_BENCH_SCENE");
  const char* bundle_path = std::getenv("GI_PRM_BENCH_BUNDLE");
  if (!scene_path || !bundle_path) {
    state.SkipWithError("set GI_PRM_BENCH_SCENE and GI_PRM_BENCH_BUNDLE");
    return;
  }
  engine::Scene scene = engine::instantiate(or_exit(engine::load_gltf(scene_path)));
  engine::update_world_transforms(scene.registry);
  const gi::BakeInput input = gi::bake_input_from(scene);
  const gi::BakeLight* light = nullptr;
  for (const gi::BakeLight& l : input.lights)
    if (l.light.moves && !light) light = &l;
  if (!light) {
    state.SkipWithError("the scene has no moving light");
    return;
  }
  const auto l0 = Clock::now();
  const gi::Prm prm = or_exit(gi::load_prm(bundle_path, input));
  const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - l0).count();
  const auto caster = or_exit(gi::make_static_caster(input));
  (void)bench::gl_context();
  gi::PrmGpuPass pass = or_exit(gi::PrmGpuPass::create(prm, {.encoding = gi::PrmPaneEncoding::SharedExponent}));
  std::vector<glm::mat4> poses;
  for (int i = 0; i < 8; ++i)
    poses.push_back(glm::translate(glm::mat4(1.0f), glm::vec3(0.5f * static_cast<float>(i - 4), 0.0f, 0.0f)) *
                    light->light_to_world);
  (void)pass.run({});
  glFinish();
  std::vector<double> cpu, gpu, cpu_time, gpu_time;
  std::size_t frame = 0, clusters = 0;
  for (auto _ : state) {
    const double c0 = process_cpu_ms();
    const auto t0 = Clock::now();
    const gi::ReferenceLight ref = gi::reference_light(light->light, poses[frame++ % poses.size()]);
    const std::vector<gi::PointEmitter> emitters =
        gi::light_point_emitters(std::span<const gi::ReferenceLight>(&ref, 1), 16, prm.settings.seed);
    const std::vector<glm::vec3> entry = gi::entry_irradiance(prm, emitters, *caster, nullptr);
    const std::vector<gi::ClusterWeight> picked = gi::select_clusters(gi::cluster_weights(prm, entry), 32);
    const auto t1 = Clock::now();
    const double c1 = process_cpu_ms();
    if (!pass.run(picked)) state.SkipWithError("PrmGpuPass::run failed");
    glFinish();
    const auto t2 = Clock::now();
    cpu_time.push_back(c1 - c0);
    gpu_time.push_back(process_cpu_ms() - c1);
    cpu.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    gpu.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    clusters = picked.size();
  }
  const gi::PrmGpuPass::Memory m = pass.memory();
  const auto mb = [](double bytes) { return bytes / 1e6; };
  state.counters["gpu_mb"] = mb(static_cast<double>(m.total()));
  state.counters["gpu_panes_mb"] = mb(static_cast<double>(m.panes));
  state.counters["gpu_texels_mb"] = mb(static_cast<double>(m.texels));
  state.counters["gpu_upsample_mb"] = mb(static_cast<double>(m.upsample));
  state.counters["gpu_coarse_mb"] = mb(static_cast<double>(m.coarse));
  state.counters["gpu_output_mb"] = mb(static_cast<double>(m.output));
  state.counters["gpu_work_mb"] = mb(static_cast<double>(m.work));
  state.counters["cpu_panes_mb"] = mb(static_cast<double>(prm.panes.values.size() * sizeof(float)));
  if (prm.atlas) {
    const gi::PaneUpsampler& up = *prm.atlas->upsampler;
    state.counters["cpu_upsample_mb"] =
        mb(static_cast<double>(up.reads().size() * sizeof(gi::PaneUpsampler::Read) +
                               up.ring_texels().size() * sizeof(gi::PaneUpsampler::RingTexel)));
    state.counters["upsample_old_format_mb"] = mb(static_cast<double>(old_format_upsample_bytes(up)));
    state.counters["upsample_reads"] = static_cast<double>(up.reads().size());
    state.counters["upsample_ring_texels"] = static_cast<double>(up.ring_texels().size());
  }
  state.counters["pane_texels"] = static_cast<double>(prm.texels.size());
  state.counters["pane_layout_texels"] = static_cast<double>(prm.width) * static_cast<double>(prm.height);
  state.counters["atlas_texels"] = static_cast<double>(prm.atlas_width()) * static_cast<double>(prm.atlas_height());
  state.counters["stored_elements"] = static_cast<double>(prm.panes.stored_elements());
  state.counters["pane_blocks"] = static_cast<double>(prm.panes.blocks.size());
  state.counters["clusters"] = static_cast<double>(clusters);
  state.counters["load_ms"] = load_ms;
  state.counters["cpu_ms"] = median(cpu);
  state.counters["gpu_ms"] = median(gpu);
  state.counters["cpu_cpu_time_ms"] = median(cpu_time);
  state.counters["gpu_cpu_time_ms"] = median(gpu_time);
  if (const char* preset = std::getenv("GI_PRM_BENCH_REBAKE")) {
    gi::BakeInput fixed = input;
    for (gi::BakeLight& l : fixed.lights) l.light.moves = false;
    const auto b0 = Clock::now();
    const auto atlas = or_exit(gi::bake_light_atlas(fixed, or_exit(gi::light_atlas_preset(preset))));
    const double rebake_ms = std::chrono::duration<double, std::milli>(Clock::now() - b0).count();
    benchmark::DoNotOptimize(atlas.irradiance.data());
    state.counters["atlas_rebake_ms"] = rebake_ms;
    state.counters["vs_rebake"] = rebake_ms / (median(cpu) + median(gpu));
  }
}
BENCHMARK(BM_PrmBundle)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(16);

// The CPU part's two ray sets alone, on the same poses: the flux check (64^2 directions from
// the lamp, closest hits) and the entry points' shadow rays with their kernels (no flux check).
std::vector<gi::PointEmitter> lamp_emitters(const DemoLevel& d, int pose) {
  const glm::vec3 pivot = glm::vec3(d.lamp_world[3]) + glm::vec3(0.0f, 1.35f, 0.0f);
  const float angle = glm::radians(-20.0f + 5.0f * static_cast<float>(pose % 8));
  const glm::mat4 m = glm::translate(glm::mat4(1.0f), pivot) * glm::rotate(glm::mat4(1.0f), angle, glm::vec3(0, 0, 1)) *
                      glm::translate(glm::mat4(1.0f), -pivot) * d.lamp_world;
  const gi::ReferenceLight ref = gi::reference_light(d.lamp, m);
  return gi::light_point_emitters(std::span<const gi::ReferenceLight>(&ref, 1), 16, d.prm.settings.seed);
}

// Argument: threads tracing the rays (1: the calling thread).
void BM_PrmFluxCheck(benchmark::State& state) {
  const DemoLevel& d = demo_level();
  std::unique_ptr<gi::ThreadPool> pool;
  if (state.range(0) > 1) pool = std::make_unique<gi::ThreadPool>(static_cast<unsigned>(state.range(0)));
  int pose = 0;
  for (auto _ : state) {
    const std::vector<gi::PointEmitter> e = lamp_emitters(d, pose++);
    std::vector<gi::LitDirection> hits;
    benchmark::DoNotOptimize(gi::punctual_lit_solid_angle(e[0], *d.caster, 64, &hits, pool.get()));
  }
}
BENCHMARK(BM_PrmFluxCheck)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->MinTime(1.0);

// Argument: 1 traces the shadow rays together in packets (RayCaster::occluded_coherent, what
// entry_irradiance does), 0 one by one (emitter_visible). Both are checked to agree ray for ray
// on the 8 poses first (the run stops with an error if not).
void BM_PrmEntryShadowRays(benchmark::State& state) {
  const DemoLevel& d = demo_level();
  const bool coherent = state.range(0) != 0;
  const auto shadow_rays = [&](const gi::PointEmitter& e) {
    std::vector<gi::Ray> rays;
    for (const gi::PrmEntryPoint& p : d.prm.entries)
      if (gi::emitter_irradiance(e, p.position, p.normal, p.area_m2) != glm::vec3(0.0f))
        rays.push_back(gi::emitter_shadow_ray(e, p.position, p.normal));
    return rays;
  };
  std::size_t checked = 0;
  for (int pose = 0; pose < 8; ++pose) {
    const std::vector<gi::PointEmitter> e = lamp_emitters(d, pose);
    const std::vector<gi::Ray> rays = shadow_rays(e[0]);
    std::vector<std::uint8_t> blocked(rays.size());
    d.caster->occluded_coherent(rays, blocked);
    std::size_t i = 0;
    for (const gi::PrmEntryPoint& p : d.prm.entries) {
      if (gi::emitter_irradiance(e[0], p.position, p.normal, p.area_m2) == glm::vec3(0.0f)) continue;
      if ((blocked[i++] != 0) == gi::emitter_visible(*d.caster, e[0], p.position, p.normal)) {
        state.SkipWithError("occluded_coherent and emitter_visible disagree");
        return;
      }
      ++checked;
    }
  }
  int pose = 0;
  std::vector<std::uint8_t> blocked;
  for (auto _ : state) {
    const std::vector<gi::PointEmitter> e = lamp_emitters(d, pose++);
    std::size_t lit = 0;
    if (coherent) {
      const std::vector<gi::Ray> rays = shadow_rays(e[0]);
      blocked.resize(rays.size());
      d.caster->occluded_coherent(rays, blocked);
      for (std::uint8_t b : blocked) lit += b == 0;
    } else {
      for (const gi::PrmEntryPoint& p : d.prm.entries) {
        const glm::vec3 irr = gi::emitter_irradiance(e[0], p.position, p.normal, p.area_m2);
        if (irr == glm::vec3(0.0f)) continue;
        lit += gi::emitter_visible(*d.caster, e[0], p.position, p.normal);
      }
    }
    benchmark::DoNotOptimize(lit);
  }
  state.counters["rays_checked"] = static_cast<double>(checked);
}
BENCHMARK(BM_PrmEntryShadowRays)
    ->ArgName("packets")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
