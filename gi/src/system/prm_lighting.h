#pragma once
// The runtime side of precomputed radiance maps (PRM): an engine::IndirectLightProvider
// whose irradiance atlas follows the scene's moving lights (the flashlight, a swinging
// lamp), optionally on top of a light atlas baked for the static lights. Each frame it
// checks the moving lights; only when one changed (moved, turned, switched, dimmed) it
// recomputes that light's entry-point irradiance (CPU, shadow rays against the static
// world; the other lights' is cached), sums them into the cluster weights, picks the K
// heaviest clusters and re-sums their panes on the GPU. A frame where nothing moved does
// nothing.
// Internal to GISystem, which loads bundles.
//   auto gi = gi::PrmLighting::from_bake(std::move(prm), &atlas, scene).value();
//   renderer->set_indirect_light(gi.get());
//
// It leaves the scene as it is and hands the renderer the static meshes with TEXCOORD_1
// through atlas_meshes() (see LightAtlasLighting). The provider
// reads lights from `scene.registry`, which must outlive it. GL objects are created on the
// first frame() (the context must be current) and deleted with the provider.

#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <gi/log.h>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

struct Prm;
struct PrmEntryPoint;
struct LightAtlasBake;
struct AtlasLayout;
class RayCaster;

struct PrmLightingSettings {
  int active_clusters = 32;  ///< K: panes summed per update (the heaviest); 0: all.
  LogCallback log;           ///< Told when the GPU pass cannot run (the PRM turns off).
  /// Panes in GPU memory as RGB9E5 (4 bytes per element) instead of half floats (6): a third
  /// fewer bytes per light change, at <= 2e-3 of a texel's largest channel per pane value
  /// (docs/prm.md "Pane encoding").
  bool shared_exponent_panes = true;
  /// Threads tracing a moving light's flux check (4096 rays, ~0.12 ms of the update's CPU
  /// part) on an update; 0: the hardware's (at most 4). The result does not depend on it.
  /// Default 1 (the calling thread): two threads pay only where a core is idle; with the
  /// cores busy they were slower (prm_relight_bench BM_PrmFluxCheck/threads:2, docs/performance.md).
  unsigned threads = 1;
};

class PrmLighting final : public engine::IndirectLightProvider {
 public:
  /// From bakes in memory (base may be null). Same layout required.
  static engine::Result<std::unique_ptr<PrmLighting>> from_bake(
      Prm prm, const LightAtlasBake* base, const engine::Scene& scene, PrmLightingSettings settings = {},
      std::shared_ptr<const RayCaster> static_world = nullptr);

  PrmLighting(const PrmLighting&) = delete;
  PrmLighting& operator=(const PrmLighting&) = delete;
  ~PrmLighting() override;

  /// The irradiance atlas for this frame (re-summed only when a moving light changed).
  const engine::IndirectLightFrame& frame() override;
  const char* label() const override;
  /// The static meshes with the PRM's atlas as TEXCOORD_1 (gi::atlas_meshes_of).
  std::span<const engine::AtlasMesh> atlas_meshes() const override;

  struct Stats {
    std::uint64_t frames = 0;
    std::uint64_t updates = 0;     ///< Frames on which the atlas was recomputed.
    double last_weights_ms = 0.0;  ///< CPU: entry weights, cluster means, selection.
    double last_gpu_ms = 0.0;      ///< GPU pane sum (glFinish-timed: CPU time on llvmpipe).
    std::size_t last_active_clusters = 0;
    std::size_t last_lights_recomputed = 0;  ///< Moving lights whose entry irradiance was recomputed last update,
    std::size_t last_lights_reused = 0;      ///< and those whose cached one was reused (they had not changed).
    std::size_t gpu_bytes = 0;
    std::string disabled;  ///< Why the PRM turned off (no GPU resources, a failed update); empty: running.
  };
  const Stats& stats() const;

  // Read-only, for the world probes that light dynamic objects (system/prm_probe_light.h):
  // the moving lights' first bounce off the static world as emitters.
  /// The PRM's entry points (where moving lights first hit the static world).
  std::span<const PrmEntryPoint> entry_points() const;
  /// The atlas layout the panes are drawn at (the static meshes' TEXCOORD_1).
  const AtlasLayout& layout() const;
  /// Per entry point, the moving lights' irradiance (W/m^2) as of the last update (the cached
  /// per-light values summed); zeros before the first frame.
  std::vector<glm::vec3> moving_entry_irradiance() const;
  /// Changes whenever the entry irradiance does (the update counter).
  std::uint64_t entry_version() const { return stats().updates; }

 private:
  struct Impl;
  explicit PrmLighting(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
