// Basis radiance fields, CPU runtime: milliseconds per update for 1, 5, 10 and 30 crates
// (pairs grow as n^2) with the I_c pair culling (§5.4) on and off, and the precomputed
// memory per object. Crates share one mesh, basis and field (instanced props).
//   ./build/benchmarks/brf_bench --benchmark_counters_tabular=true
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/gtc/matrix_transform.hpp>

#include "brf/brf_runtime.h"

namespace {

gi::BrfMesh crate(float half, int n) {
  gi::BrfMesh m;
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a)
    for (float sign : {-1.0f, 1.0f}) {
      const glm::vec3 nrm = axes[a] * sign;
      const glm::vec3 t = axes[(a + 1) % 3] * sign, b = axes[(a + 2) % 3];
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          const float s = (2.0f * static_cast<float>(i) / static_cast<float>(n) - 1.0f) * 0.98f;
          const float r = (2.0f * static_cast<float>(j) / static_cast<float>(n) - 1.0f) * 0.98f;
          m.positions.push_back((nrm + s * t + r * b) * half);
          m.normals.push_back(nrm);
        }
      const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

struct Shared {
  gi::BrfMesh mesh = crate(0.25f, 4);
  gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = 16}).value();
  gi::BasisRadianceField field = gi::compute_basis_radiance_field(mesh, basis, {}).value();
};

const Shared& shared() {
  static const Shared s;
  return s;
}

void BM_BrfUpdate(benchmark::State& state) {
  const Shared& s = shared();
  const int n = static_cast<int>(state.range(0));
  const bool cull = state.range(1) != 0;
  std::vector<gi::BrfObject> objects;
  // Crates on a floor-like grid, 1.2 m apart: far pairs exchange little light.
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  for (int i = 0; i < n; ++i)
    objects.push_back({&s.mesh, &s.basis, &s.field,
                       glm::translate(glm::mat4(1.0f), {1.2f * static_cast<float>(i % side), 0.25f, 1.2f * static_cast<float>(i / side)}),
                       glm::vec3(0.8f, 0.3f + 0.05f * static_cast<float>(i % 5), 0.2f)});
  gi::PointEmitter light;
  light.position = {0.5f * static_cast<float>(side), 3.0f, 0.5f * static_cast<float>(side)};
  light.radiant = glm::vec3(20.0f);
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

}  // namespace

BENCHMARK_MAIN();
