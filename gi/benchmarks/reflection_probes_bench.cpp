// The forward pass's cost of the reflection probes' lookup (docs/reflection_probes.md, "The
// lobe at the view"): the split sum's single read (lobe_samples 0, the yardstick, measured in
// the same run) against filtered importance sampling with 4, 8, 16 and 32 samples of the lobe
// and the runtime's count (4 along the normal, doubling as the view grazes, up to 32), each
// sample a parallax search and a trilinear read. On the demo level, baked at preview
// (every method its plan asks for; its corridor floor of roughness 0.15 reads the probes),
// from its camera 0 (the hub, looking through the doorway down the corridor) and from the
// corridor's floor looking down it (most pixels read the probes). The renderer's
// GPU timer gives the forward pass's milliseconds (on llvmpipe: CPU time of the rasterizer).
//   ./build/gi/benchmarks/reflection_probes_bench --benchmark_counters_tabular=true
// The bundle is baked once into the temporary directory (reflection_probes_bench_demo.gibake)
// and re-baked when it no longer loads.
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/renderer.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/bake_input.h>
#include <gi/gi_system.h>

#include <benchmark/benchmark.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "bench_gl.h"

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "reflection_probes_bench: %s\n", what.c_str());
  std::exit(1);
}

// The GI system's frame with the probes' lookup replaced (the runtime asks for
// gi::kProbeLobeSamples; the benchmark tries each count on the same bundle).
class LobeOverride : public engine::IndirectLightProvider {
 public:
  LobeOverride(gi::GISystem& gi, int samples, int samples_max) : gi_(gi), samples_(samples), max_(samples_max) {}
  const engine::IndirectLightFrame& frame() override {
    frame_ = gi_.frame();
    frame_.reflection_probe_lobe_samples = samples_;
    frame_.reflection_probe_lobe_samples_max = max_;
    return frame_;
  }
  std::span<const engine::AtlasMesh> atlas_meshes() const override { return gi_.atlas_meshes(); }
  const char* label() const override { return gi_.label(); }

 private:
  gi::GISystem& gi_;
  int samples_, max_;
  engine::IndirectLightFrame frame_;
};

struct Demo {
  engine::Scene scene;
  std::unique_ptr<gi::GISystem> gi;
  std::unique_ptr<engine::Renderer> renderer;  // declared last: destroyed before the GI system
  engine::Entity camera;
  engine::Transform camera0;  ///< Camera 0's own placement.
};

Demo& demo() {
  static Demo d = [] {
    (void)bench::gl_context();
    auto asset = engine::load_gltf(fs::path(GI_SOURCE_DIR) / "assets" / "demo_level.gltf");
    if (!asset) fail(asset.error().to_string());
    const fs::path bundle = fs::temp_directory_path() / "reflection_probes_bench_demo.gibake";
    Demo out;
    out.scene = engine::instantiate(*asset);
    auto gi = gi::GISystem::load(bundle, out.scene);
    if (!gi) {
      std::fprintf(stderr, "reflection_probes_bench: baking the demo level at preview into %s\n", bundle.c_str());
      fs::remove_all(bundle);
      auto report = gi::bake_bundle(gi::bake_input_from(out.scene), bundle, {.preset = "preview"});
      if (!report) fail(report.error().to_string());
      gi = gi::GISystem::load(bundle, out.scene);
      if (!gi) fail(gi.error().to_string());
    }
    out.gi = std::move(gi).value();
    engine::RenderSettings s;
    s.width = 640;
    s.height = 360;
    auto r = engine::Renderer::create(out.scene.assets, s);
    if (!r) fail(r.error().to_string());
    out.renderer = std::move(r).value();
    out.camera = engine::find_camera(out.scene.registry);
    out.camera0 = out.scene.registry.get<engine::Transform>(out.camera);
    return out;
  }();
  return d;
}

double forward_ms(const engine::Renderer& r) {
  for (const engine::PassTiming& t : r.last_timings())
    if (t.name.rfind("forward", 0) == 0) return t.ms;
  fail("no forward pass in the renderer's timings");
}

void place_camera(Demo& d, const engine::Transform& t) {
  d.scene.registry.begin_frame();
  d.scene.registry.write<engine::Transform>(d.camera) = t;
  engine::update_world_transforms(d.scene.registry);
}

// On the corridor's floor (box [3, 5] x [0, 3] x [8, 16.4] m), 0.6 m up, looking down it: most
// pixels are its glossy floor (every one reads the probes) and its walls, the worst case.
engine::Transform corridor_view(const engine::Transform& camera0) {
  engine::Transform t = camera0;
  const glm::vec3 eye(4.0f, 0.6f, 8.6f), target(4.0f, 0.0f, 16.0f);
  t.position = eye;
  t.rotation = glm::normalize(glm::quat_cast(glm::mat3(glm::inverse(glm::lookAt(eye, target, glm::vec3(0, 1, 0))))));
  return t;
}

void time_forward(benchmark::State& state, Demo& d) {
  LobeOverride provider(*d.gi, static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  d.renderer->set_indirect_light(&provider);
  d.renderer->render(d.scene.registry, d.camera);  // warm-up: uploads, shader variants
  for (auto _ : state) {
    d.renderer->render(d.scene.registry, d.camera);
    state.SetIterationTime(forward_ms(*d.renderer) / 1000.0);
  }
  d.renderer->set_indirect_light(nullptr);
  state.counters["lobe_samples"] = static_cast<double>(state.range(0));
  state.counters["lobe_samples_max"] = static_cast<double>(state.range(1));
}

// Camera 0's own placement.
engine::Transform camera0_view(const engine::Transform& camera0) { return camera0; }

// The forward pass from one view, the lobe samples state.range(0) at views along the normal, up to
// state.range(1) at grazing views (gi::probe_lobe_sample_count; at most range(0): a fixed count).
void BM_ForwardPass(benchmark::State& state, engine::Transform (*view)(const engine::Transform&)) {
  Demo& d = demo();
  place_camera(d, view(d.camera0));
  time_forward(state, d);
}

// Interleaved yardstick: the split sum (0) first and last. 4 / 32: the runtime's count (4 along
// the normal, up to 32 at grazing views); the others fixed counts.
void lobe_sample_counts(benchmark::internal::Benchmark* b) {
  const std::pair<int, int> counts[] = {{0, 0}, {4, 4}, {4, 32}, {8, 8}, {16, 16}, {32, 32}, {0, 0}};
  for (const auto& [samples, most] : counts) b->Args({samples, most});
  b->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);
}

BENCHMARK_CAPTURE(BM_ForwardPass, DemoCamera0, camera0_view)->Apply(lobe_sample_counts);
BENCHMARK_CAPTURE(BM_ForwardPass, CorridorFloor, corridor_view)->Apply(lobe_sample_counts);

}  // namespace

BENCHMARK_MAIN();
