// The light atlas's final gather by stage (light_atlas/texel_gather.h) on the Cornell box,
// against the yardstick of the same number of closest-hit rays cast straight through the
// bake's Embree caster from the same texels (no lookups, no shading): the gather's ray
// stages cannot be faster than that, and the gap is what its bookkeeping costs.
//   ./build/gi/benchmarks/light_atlas_bench
// Counters: seconds per stage of one bake and million rays per second.
#include <benchmark/benchmark.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake_input.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/random.h"
#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/texel_gather.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"
#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace {

struct Fixture {
  gi::AtlasLayout layout;
  gi::StaticBakeScene scene;
};

const gi::BakeInput& cornell_input() {
  static const gi::BakeInput input = [] {
    auto asset = engine::load_gltf(std::string(GI_SOURCE_DIR) + "/assets/cornell_box.gltf");
    if (!asset) {
      std::fprintf(stderr, "%s\n", asset.error().to_string().c_str());
      std::abort();
    }
    return gi::bake_input_from(engine::instantiate(std::move(asset).value()));
  }();
  return input;
}

const Fixture& cornell(float density) {
  static Fixture f = [density] {
    const gi::BakeInput& input = cornell_input();
    Fixture out;
    out.layout = gi::build_atlas_layout(gi::atlas_inputs_from(input), {.texels_per_metre = density}).value();
    out.scene =
        gi::prepare_static_scene(input, out.layout, gi::BakeLights::Static, gi::TexelPlacement::VisibleSurface).value();
    return out;
  }();
  return f;
}

constexpr float kDensity = 64.0f;

void BM_GatherStages(benchmark::State& state) {
  const Fixture& f = cornell(kDensity);
  gi::ThreadPool pool(2);
  const gi::TexelGatherSettings s{.direct_samples = 16,
                                  .solve_rays = static_cast<int>(state.range(0)),
                                  .gather_rays = static_cast<int>(state.range(1)),
                                  .filter_radius_texels = 1.5f};
  gi::TexelGatherResult last;
  for (auto _ : state) {
    auto r = gi::gather_atlas(f.scene, f.layout, s, pool);
    if (!r) {
      state.SkipWithError(r.error().to_string().c_str());
      return;
    }
    last = std::move(r).value();
    benchmark::DoNotOptimize(last.indirect.data());
  }
  state.counters["direct_s"] = last.direct_seconds;
  state.counters["solve_s"] = last.solve_seconds;
  state.counters["gather_s"] = last.gather_seconds;
  state.counters["filter_s"] = last.filter_seconds;
  state.counters["iterations"] = last.iterations;
  state.counters["Mrays/s"] =
      benchmark::Counter(static_cast<double>(last.rays) * 1e-6 * state.iterations(), benchmark::Counter::kIsRate);
}

// The yardstick: cosine rays from every valid texel through the same caster, closest hit,
// nothing done with the hit.
void BM_RawClosestHitRays(benchmark::State& state) {
  const Fixture& f = cornell(kDensity);
  gi::ThreadPool pool(2);
  const gi::AtlasTexels& tx = f.scene.texels;
  std::vector<std::uint32_t> work;
  for (std::size_t i = 0; i < tx.valid.size(); ++i)
    if (tx.valid[i]) work.push_back(static_cast<std::uint32_t>(i));
  const auto rays_per_texel = static_cast<int>(state.range(0));
  std::uint64_t rays = 0;
  for (auto _ : state) {
    std::atomic<std::uint64_t> hits{0};
    pool.parallel_for(
        work.size(),
        [&](std::size_t w) {
          const std::uint32_t i = work[w];
          gi::Pcg32 rng = gi::Pcg32::for_item(7, i);
          const glm::vec3 origin = gi::offset_ray_origin(tx.position[i], tx.normal[i]);
          std::uint64_t local = 0;
          for (int r = 0; r < rays_per_texel; ++r) {
            const glm::vec3 d = gi::sample_cosine_hemisphere(tx.normal[i], rng.next_float(), rng.next_float());
            local += f.scene.caster->intersect(gi::Ray{origin, 0.0f, d}).valid();
          }
          hits += local;
        },
        64);
    benchmark::DoNotOptimize(hits.load());
    rays += work.size() * static_cast<std::uint64_t>(rays_per_texel);
  }
  state.counters["Mrays/s"] = benchmark::Counter(static_cast<double>(rays) * 1e-6, benchmark::Counter::kIsRate);
}

// A whole bake (gi-bake's path: layout, scene preparation, VPLs, gather) on the Cornell box
// at 128 texels/m (33.5k texels, the table), by stage: the fixed costs that a
// preview bake cannot ray-count its way out of. Args: kept rays, fresh rays, filter (tenths
// of a texel). Process CPU time is reported too: the machine is shared.
void BM_BakeEndToEnd(benchmark::State& state) {
  const gi::BakeInput& input = cornell_input();
  gi::LightAtlasSettings s;
  s.texels_per_metre = 128.0f;
  s.vpl_count = 300;
  s.final_pass = gi::LightAtlasSettings::FinalPass::TexelGather;
  s.gather.solve_rays = static_cast<int>(state.range(0));
  s.gather.gather_rays = static_cast<int>(state.range(1));
  s.gather.filter_radius_texels = static_cast<float>(state.range(2)) / 10.0f;
  s.threads = 2;
  gi::LightAtlasStats st;
  for (auto _ : state) {
    auto bake = gi::bake_light_atlas(input, s);
    if (!bake) {
      state.SkipWithError(bake.error().to_string().c_str());
      return;
    }
    st = bake->stats;
    benchmark::DoNotOptimize(bake->irradiance.data());
  }
  state.counters["layout_s"] = st.layout_seconds;
  state.counters["prepare_s"] = st.prepare_seconds;
  state.counters["vpl_s"] = st.vpl_seconds;
  state.counters["direct_s"] = st.direct_seconds;
  state.counters["final_s"] = st.final_seconds;
  state.counters["total_s"] = st.total_seconds;
}

}  // namespace

BENCHMARK(BM_BakeEndToEnd)
    ->Args({4, 0, 25})
    ->Args({16, 0, 25})
    ->Args({64, 256, 25})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
// (kept rays, fresh rays): the medium and high presets' ray counts.
BENCHMARK(BM_GatherStages)->Args({64, 256})->Args({128, 512})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RawClosestHitRays)->Arg(320)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
