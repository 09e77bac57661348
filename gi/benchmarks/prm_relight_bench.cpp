// One PRM light change on the demo level's preview bake (assets/demo_level.gltf, the PRM and
// light atlas presets gi-bake uses for `--preset preview`), the path PrmLighting::frame()
// takes when one moving light changed: the swinging lamp swung to a new pose, its point
// emitters, entry irradiance (shadow rays against the static world, flux check), cluster
// weights, the K = 32 heaviest clusters, and the GPU pane sum with glFinish.
// The yardstick, measured in the same run: re-baking the light atlas (preview) for the
// change, which is what a light without the PRM would cost.
//   ./build/gi/benchmarks/prm_relight_bench --benchmark_counters_tabular=true
// Counters (medians over the iterations): cpu_ms (emitters, entry irradiance, weights,
// selection), gpu_ms (pane sum + glFinish; CPU time on llvmpipe), atlas_rebake_ms (one bake
// before the loop), vs_rebake = atlas_rebake_ms / (cpu_ms + gpu_ms) (issue 23 target >= 1000),
// clusters (selected), texels (pane elements), gpu_k0_ms (the pane sum with no cluster: its
// fixed part, the texel list read and every texel written), nonzero_blocks (share of the
// panes' blocks of 8 elements holding any non-zero value).
#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake_input.h>
#include <glm/gtc/matrix_transform.hpp>

#include "bench_gl.h"

#include "light_atlas/light_atlas.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
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
  gi::Prm prm;
  std::unique_ptr<gi::RayCaster> caster;
  engine::Light lamp;
  glm::mat4 lamp_world{1.0f};
};

const DemoLevel& demo_level() {
  static const DemoLevel d = [] {
    DemoLevel out;
    engine::Scene scene = engine::instantiate(or_exit(engine::load_gltf(std::string(GI_SOURCE_DIR) + "/assets/demo_level.gltf")));
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
    out.prm = or_exit(gi::bake_prm(out.input, or_exit(gi::prm_preset("preview"))));
    out.caster = or_exit(gi::make_static_caster(out.input));
    return out;
  }();
  return d;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

void BM_PrmLightChange(benchmark::State& state) {
  const DemoLevel& d = demo_level();
  (void)bench::gl_context();
  gi::PrmGpuPass pass = or_exit(gi::PrmGpuPass::create(d.prm));
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
  (void)pass.run({});  // first-dispatch shader compilation in llvmpipe
  glFinish();
  std::vector<double> cpu, gpu;
  std::size_t frame = 0, clusters = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const gi::ReferenceLight ref = gi::reference_light(d.lamp, poses[frame++ % poses.size()]);
    const std::vector<gi::PointEmitter> emitters =
        gi::light_point_emitters(std::span<const gi::ReferenceLight>(&ref, 1), 16, d.prm.settings.seed);
    const std::vector<glm::vec3> entry = gi::entry_irradiance(d.prm, emitters, *d.caster);
    const std::vector<gi::ClusterWeight> picked = gi::select_clusters(gi::cluster_weights(d.prm, entry), kActive);
    const auto t1 = Clock::now();
    if (!pass.run(picked)) state.SkipWithError("PrmGpuPass::run failed");
    glFinish();
    const auto t2 = Clock::now();
    cpu.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    gpu.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    clusters = picked.size();
  }
  // The pane sum's fixed part: no cluster selected (the texel list read, every texel written).
  std::vector<double> empty;
  for (int i = 0; i < 20; ++i) {
    const auto t0 = Clock::now();
    (void)pass.run({});
    glFinish();
    empty.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  state.counters["gpu_k0_ms"] = median(empty);
  const double cpu_ms = median(cpu), gpu_ms = median(gpu);
  state.counters["cpu_ms"] = cpu_ms;
  state.counters["gpu_ms"] = gpu_ms;
  state.counters["total_ms"] = cpu_ms + gpu_ms;
  state.counters["atlas_rebake_ms"] = rebake_ms;
  state.counters["vs_rebake"] = rebake_ms / (cpu_ms + gpu_ms);
  state.counters["clusters"] = static_cast<double>(clusters);
  state.counters["texels"] = static_cast<double>(d.prm.texels.size());
  state.counters["entries"] = static_cast<double>(d.prm.entries.size());
  {
    const std::size_t n = d.prm.texels.size();
    std::size_t nonzero = 0, total = 0;
    for (int c = 0; c < d.prm.cluster_count; ++c)
      for (std::size_t first = 0; first < n; first += 8, ++total) {
        bool any = false;
        for (std::size_t i = first; i < std::min(n, first + 8) && !any; ++i)
          for (int ch = 0; ch < 3; ++ch) any |= d.prm.panes[(std::size_t(c) * n + i) * 3 + ch] != 0.0f;
        nonzero += any;
      }
    state.counters["nonzero_blocks"] = double(nonzero) / double(total);
  }
}
BENCHMARK(BM_PrmLightChange)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
