#pragma once
// The GI system a game adds to its frame loop: it loads a bake bundle (gi-bake's output)
// and hands the renderer the indirect light of every frame, recomputing only what changed.
//
//   engine::Scene scene = engine::instantiate(engine::load_gltf("level.gltf").value());
//   auto renderer = engine::Renderer::create(scene.assets, {}).value();  // before or after load
//   auto gi = gi::GISystem::load("out/level.gibake", scene);
//   if (!gi) { std::cerr << gi.error().to_string() << '\n'; return 1; }
//   renderer->set_indirect_light(gi.value().get());             // frame() runs once per drawn frame
//   // ... game loop: simulate (move crates, lights), then renderer->render(...)
//
// What runs, from what the bundle holds (gi-bake bakes what gi::plan() asks for):
//   light atlas  static world, static lights: uploaded once;
//   PRM          moving lights: entry weights and the pane sum only on frames where a
//                moving light changed;
//   DLM          glossy static surfaces (directional light maps): uploaded once; the
//                renderer integrates the specular lobe against them for the view, per pixel;
//   BRF          dynamic rigid objects: per-vertex indirect light (world probes + light
//                interreflected between objects, GPU), their bounce added into the static
//                atlas; only on frames where an object moved or any light changed, and the
//                basis irradiance only for pairs whose relative pose changed;
//   antiradiance deforming regions (a door): on frames where a deforming node moved, its
//                elements relinked, the iteration on the GPU, the change against the baked
//                pose added into the atlas (docs/antiradiance.md).
// A frame where nothing changed does no work (Stats counts it).
//
// Loading checks every file against the scene (a bundle baked from other geometry, or from
// other meshes, is rejected naming the file and both hashes). It does not change the scene:
// the static meshes with TEXCOORD_1 reach the renderer through atlas_meshes()
// (engine/indirect_light.h), so the renderer may be created before or after load(). The
// scene's registry must
// outlive the system; GL objects are created on the first frame() (context current) and
// deleted with the system: destroy it before the GL context.

#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <gi/log.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace gi {

struct GISystemSettings {
  int prm_active_clusters = 32;  ///< PRM: panes summed per update (the heaviest K; 0: all).
  /// PRM: panes in GPU memory as RGB9E5 (4 bytes a texel) instead of half floats (6), a third
  /// fewer bytes per light change; <= 2e-3 of a texel's largest channel (docs/prm.md).
  bool prm_shared_exponent_panes = true;
  int brf_bounces = 3;               ///< BRF: bounces between dynamic objects.
  float brf_cull_threshold = 1e-3f;  ///< BRF: skip object pairs below this share of the largest (§5.4).
  float probe_spacing_m = 1.0f;      ///< BRF: spacing of the world-light probes for dynamic objects.
  /// BRF: GPU memory for the object pairs' basis irradiance (bytes; 0: the GPU's largest
  /// buffer, 128 MiB on llvmpipe). When the pairs in reach need more, each object's reach
  /// narrows until they fit (Stats::brf_reach), so crowds keep their nearest neighbours' bounce.
  std::size_t brf_pair_budget_bytes = 0;
  /// Told when a method turns off at run time (e.g. its GPU pass cannot be created); the
  /// system never prints. Stats::disabled keeps the same facts for a host without a log.
  LogCallback log;
};

class GISystem final : public engine::IndirectLightProvider {
 public:
  /// Errors: no manifest, no method the runtime uses, stale or damaged files (the message
  /// names the file and the problem).
  static engine::Result<std::unique_ptr<GISystem>> load(const std::filesystem::path& bundle_dir, engine::Scene& scene,
                                                        GISystemSettings settings = {});
  GISystem(const GISystem&) = delete;
  GISystem& operator=(const GISystem&) = delete;
  ~GISystem() override;

  /// Indirect light for the frame about to be drawn (GL context current).
  const engine::IndirectLightFrame& frame() override;
  /// "light atlas", "light atlas + PRM", "light atlas + PRM + BRF + DLM", "... + antiradiance"
  const char* label() const override;
  /// The static meshes with the atlas's TEXCOORD_1 (the light atlas's or the PRM's layout),
  /// drawn by the renderer in place of the scene's; the scene itself is not changed.
  std::span<const engine::AtlasMesh> atlas_meshes() const override;

  struct Stats {
    double load_ms = 0.0;         ///< GISystem::load: the bundle read and checked, CPU-side setup (no GL).
    double first_frame_ms = 0.0;  ///< The first frame(): GPU uploads and first composites (glFinish-timed).
    std::uint64_t frames = 0;
    std::uint64_t idle_frames = 0;        ///< Frames on which nothing was recomputed.
    std::uint64_t prm_updates = 0;        ///< Frames on which a moving light re-summed the PRM.
    std::uint64_t prm_probe_updates = 0;  ///< ... and re-projected its entry points into the BRF world probes.
    double last_prm_probe_ms = 0.0;       ///< That re-projection (CPU).
    std::uint64_t brf_updates = 0;        ///< Frames on which the dynamic objects' light was recomputed.
    std::uint64_t brf_moves = 0;          ///< ... of which at least one object had moved.
    std::uint64_t world_composites = 0;   ///< Frames on which the objects' bounce was re-added to the atlas.
    std::size_t brf_pairs_evaluated = 0;  ///< Last BRF update: object pairs with light between them,
    std::size_t brf_pairs_reused = 0;     ///< ... of which their basis irradiance was reused (pose unchanged),
    std::size_t brf_pairs_culled = 0;     ///< and pairs skipped by the I_c bound.
    /// BRF: the reach in use, as a multiple of the objects' outermost field spheres (1: as
    /// baked); below 1 after the pairs in reach outgrew brf_pair_budget_bytes (a warning was logged).
    float brf_reach = 1.0f;
    double last_prm_ms = 0.0;      ///< CPU weights + GPU sum (glFinish-timed).
    double last_brf_cpu_ms = 0.0;  ///< Direct light at vertices, probes.
    double last_brf_gpu_ms = 0.0;  ///< Interreflection pass (glFinish-timed).
    std::size_t dynamic_objects = 0;
    std::size_t dynamic_vertices = 0;
    std::size_t brf_field_bytes = 0;         ///< Basis + fields of all dynamic meshes (CPU copy).
    std::size_t load_probe_ms = 0;           ///< Probe grid computed at load.
    std::size_t dlm_texels = 0;              ///< Directional light maps: stored texels (glossy + gutter); 0: none.
    std::size_t dlm_gpu_bytes = 0;           ///< ... their radiance, directions and index texture on the GPU.
    std::uint64_t antiradiance_updates = 0;  ///< Frames on which a deforming node moved and was solved.
    std::size_t antiradiance_relinked_elements = 0;  ///< Last such frame: elements whose links were rebuilt.
    double last_antiradiance_ms = 0.0;               ///< Relink + direct light + GPU iteration (glFinish-timed).
    int antiradiance_iterations = 0;                 ///< Last such frame: iterations of its solve.
    double antiradiance_residual = 0.0;              ///< ... its final relative residual.
    /// ... it ran out of its iteration budget before the residual tolerance (a warning was logged).
    bool antiradiance_unconverged = false;
    /// ... its solve started from the previous move's solution (warm start), not from the
    /// direct light: false for the first move after load, after a solve that did not
    /// converge, and for a move back to the baked pose (nothing is solved there).
    bool antiradiance_warm = false;
    /// Last such frame: the part of last_antiradiance_ms spent in near-door visibility (its
    /// couplings' update and solve on the CPU; 0 without it, docs/antiradiance.md).
    double antiradiance_near_ms = 0.0;
    /// Light and dynamic-object entities left out of the last frame's GI because their world
    /// transform or light values are unusable (NaN, infinite, absurd: engine/runtime_limits.h).
    /// A skipped light gives no light; a skipped object keeps its last usable pose. Each is
    /// told once to GISystemSettings::log (a warning) when it starts being skipped.
    std::size_t skipped_entities = 0;
    /// Methods of the bundle that turned off at run time, with why: "PRM: <reason>",
    /// "BRF: <reason>". The frame goes on without them (label() no longer names them).
    std::vector<std::string> disabled;
  };
  const Stats& stats() const;
  /// One line per active method with what drives it, for overlays and logs.
  std::string describe() const;

 private:
  struct Impl;
  explicit GISystem(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
