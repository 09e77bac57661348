// Rays per second through gi's RayCaster wrapper against raw Embree calls on the same scene,
// with incoherent rays (random origins and directions). The raw call is the limit; the
// ratio says what the wrapper costs.
//   ./build/benchmarks/raytrace_bench --benchmark_counters_tabular=true
#include <cmath>
#include <numbers>
#include <vector>

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <glm/gtc/matrix_transform.hpp>

#include "core/random.h"
#include "raytrace/embree_ray_caster.h"

namespace {

// A field of 400 spheres-as-icosahedra-ish boxes: enough triangles to make traversal real.
gi::RtSceneData bench_scene() {
  gi::RtSceneData data;
  gi::RtGeometry g;
  const int n = 24;  // a 24x24-segment UV sphere (1104 triangles)
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const float th = std::numbers::pi_v<float> * float(i) / float(n);
      const float ph = 2 * std::numbers::pi_v<float> * float(j) / float(n);
      g.positions.emplace_back(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto a = static_cast<std::uint32_t>(i * (n + 1) + j);
      const auto b = a + static_cast<std::uint32_t>(n + 1);
      g.indices.insert(g.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  data.geometries.push_back(std::move(g));
  for (int k = 0; k < 400; ++k) {
    gi::Pcg32 rng = gi::Pcg32::for_item(3, static_cast<std::uint64_t>(k));
    const glm::vec3 p(rng.next_float() * 40 - 20, rng.next_float() * 40 - 20, rng.next_float() * 40 - 20);
    data.instances.push_back(gi::RtInstance{0, glm::scale(glm::translate(glm::mat4(1.0f), p), glm::vec3(1.5f)), false,
                                            static_cast<std::uint64_t>(k)});
  }
  return data;
}

std::vector<gi::Ray> incoherent_rays(std::size_t count) {
  std::vector<gi::Ray> rays(count);
  for (std::size_t i = 0; i < count; ++i) {
    gi::Pcg32 rng = gi::Pcg32::for_item(11, i);
    gi::Ray& r = rays[i];
    r.origin = glm::vec3(rng.next_float() * 40 - 20, rng.next_float() * 40 - 20, rng.next_float() * 40 - 20);
    const float z = 1 - 2 * rng.next_float();
    const float phi = 2 * std::numbers::pi_v<float> * rng.next_float();
    const float s = std::sqrt(std::max(0.0f, 1 - z * z));
    r.direction = {s * std::cos(phi), s * std::sin(phi), z};
  }
  return rays;
}

struct Fixture {
  std::unique_ptr<gi::RayCaster> caster = gi::make_embree_ray_caster(bench_scene()).value();
  std::vector<gi::Ray> rays = incoherent_rays(1 << 16);
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void BM_WrapperIntersect(benchmark::State& state) {
  Fixture& f = fixture();
  std::size_t hits = 0;
  for (auto _ : state) {
    for (const gi::Ray& r : f.rays) hits += f.caster->intersect(r).valid();
  }
  benchmark::DoNotOptimize(hits);
  state.counters["rays/s"] =
      benchmark::Counter(double(state.iterations() * f.rays.size()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WrapperIntersect)->Unit(benchmark::kMillisecond);

void BM_WrapperIntersectStream(benchmark::State& state) {
  Fixture& f = fixture();
  std::vector<gi::Hit> hits(f.rays.size());
  for (auto _ : state) {
    f.caster->intersect_many(f.rays, hits);
    benchmark::DoNotOptimize(hits.data());
  }
  state.counters["rays/s"] =
      benchmark::Counter(double(state.iterations() * f.rays.size()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WrapperIntersectStream)->Unit(benchmark::kMillisecond);

void BM_RawEmbreeIntersect(benchmark::State& state) {
  Fixture& f = fixture();
  auto scene = static_cast<RTCScene>(gi::embree_scene_handle(*f.caster));
  std::size_t hits = 0;
  for (auto _ : state) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (const gi::Ray& r : f.rays) {
      RTCRayHit rh{};
      rh.ray.org_x = r.origin.x;
      rh.ray.org_y = r.origin.y;
      rh.ray.org_z = r.origin.z;
      rh.ray.dir_x = r.direction.x;
      rh.ray.dir_y = r.direction.y;
      rh.ray.dir_z = r.direction.z;
      rh.ray.tnear = 0.0f;
      rh.ray.tfar = INFINITY;
      rh.ray.mask = 0xffffffffu;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene, &ctx, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  }
  benchmark::DoNotOptimize(hits);
  state.counters["rays/s"] =
      benchmark::Counter(double(state.iterations() * f.rays.size()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RawEmbreeIntersect)->Unit(benchmark::kMillisecond);

void BM_WrapperOccluded(benchmark::State& state) {
  Fixture& f = fixture();
  std::size_t occ = 0;
  for (auto _ : state)
    for (const gi::Ray& r : f.rays) occ += f.caster->occluded(r);
  benchmark::DoNotOptimize(occ);
  state.counters["rays/s"] =
      benchmark::Counter(double(state.iterations() * f.rays.size()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WrapperOccluded)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
