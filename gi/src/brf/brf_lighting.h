#pragma once
// Basis radiance fields in a running scene (Iwasaki et al. §5, the static world coupled in):
// every dynamic entity with a baked mesh gets a per-vertex indirect irradiance buffer for the
// renderer (engine::IndirectLightFrame::vertex_irradiance_buffer), and the objects' bounce
// is added into the static world's irradiance atlas. Per update, only when something changed:
//   - the entities' world transforms and every enabled light are fingerprinted; nothing runs
//     when neither changed;
//   - direct light at the objects' vertices on the CPU (Embree shadow rays against the
//     objects and the static world), plus the static world's light from the probes
//     (world_probes.h) when an object moved;
//   - the interreflection on the GPU (brf_gpu_pass.h): weights, basis irradiance of pairs
//     whose relative pose changed (the others are reused), bounces, and the bounce onto the
//     static receivers (atlas texels) inside each object's field, scaled by how much of the
//     object each texel sees past the static world (rays when the object moved);
//   - per vertex: world light + interreflected light (brf_vertex_sum.comp.glsl).
// composite_world() writes base atlas + bounce into the caller's atlas texture
// (brf_world_composite.comp.glsl).
//   auto brf = gi::BrfLighting::create(std::move(models), instances, entities, scene.registry, std::move(world),
//   {}).value(); if (brf->update()) brf->composite_world(base_texture, composite_texture, width, height); GLuint ssbo =
//   brf->vertex_buffer(crate_entity);

#include <engine/entity.h>
#include <engine/indirect_light.h>
#include <engine/registry.h>
#include <engine/result.h>
#include <gi/log.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>
#include <glm/glm.hpp>

#include "brf/brf_runtime.h"
#include "brf/pca_basis.h"
#include "brf/radiance_field.h"
#include "brf/world_probes.h"

namespace gi {

class RayCaster;

/// The static world's part (every member optional).
struct BrfWorldLink {
  /// The static world: shadows for the objects' direct light, and what hides an object from
  /// the static receivers (brf_static_visibility: no bounce through walls).
  std::shared_ptr<const RayCaster> caster;
  std::optional<WorldProbeGrid> probes;  ///< The world's light onto the objects.
  /// Static receivers: atlas texels (index y * width + x) with their world points and normals.
  std::vector<std::uint32_t> receiver_texels;
  std::vector<glm::vec3> receiver_positions;
  std::vector<glm::vec3> receiver_normals;
  int atlas_width = 0;
  int atlas_height = 0;
};

struct BrfLightingSettings {
  BrfUpdateSettings update;
  int area_light_samples = 16;  ///< Point emitters per area light for the direct light.
  /// BrfGpuPassOptions::phi_budget_bytes (0: the GPU's buffer limit). Pairs in reach needing
  /// more Phi than that narrow update.influence_scale until they fit (Stats::reach_narrowings).
  std::size_t phi_budget_bytes = 0;
  LogCallback log;  ///< Told when the GPU pass cannot run (the fields turn off).
};

class BrfLighting {
 public:
  /// instances[i] is drawn by dynamic entity entities[i]; its object_to_world is ignored (each
  /// update() reads the entity's WorldTransform). Errors: an instance's model out of range,
  /// models whose parts do not belong together, entities and instances of different counts,
  /// receiver arrays of different sizes.
  static engine::Result<std::unique_ptr<BrfLighting>> create(std::vector<BrfModel> models,
                                                             std::vector<BrfInstance> instances,
                                                             std::vector<engine::Entity> entities,
                                                             const engine::Registry& registry, BrfWorldLink world,
                                                             BrfLightingSettings settings = {});
  BrfLighting(const BrfLighting&) = delete;
  BrfLighting& operator=(const BrfLighting&) = delete;
  ~BrfLighting();

  /// With the GL context current: recomputes what changed. True when the objects' light (and
  /// so their bounce onto the world) changed this call. The first call always computes.
  bool update();
  /// The per-vertex indirect irradiance SSBO of `e` (vec4 per vertex), 0 for other entities.
  /// A glossy model's buffer goes on with its glossy terms, [k x V + j] for k = 1..K-1: E_k
  /// (world light + interreflected) times the instance's glossy colour.
  std::uint32_t vertex_buffer(engine::Entity e) const;
  /// A glossy entity's view-dependent indirect light for the renderer: the glossy terms of
  /// vertex_buffer(e) against the lobe's h_k table (BrdfSeparation::h, its octahedral map and
  /// brf_tangent_frame are the engine's convention). Empty (terms 0) for diffuse entities.
  engine::IndirectLightFrame::VertexRadianceLobes vertex_lobes(engine::Entity e) const;
  /// Copies `base_texture` (RGBA32F atlas, width x height) into `composite_texture` (same
  /// size and format), darkens it where the objects block the baked light
  /// (BrfResult::static_occlusion) and adds their bounce at the static receivers.
  void composite_world(std::uint32_t base_texture, std::uint32_t composite_texture) const;
  bool has_static_receivers() const;
  /// Light added to the world probes' static light (the moving lights' first bounce off the
  /// static world, system/prm_probe_light.h): radiance SH per probe of BrfWorldLink::probes,
  /// replacing the last call's. Every object's world light is re-gathered on the next
  /// update(). False (nothing changed) without probes or for another probe count.
  bool set_moving_world_light(std::span<const std::array<glm::vec3, 9>> radiance_sh);

  struct Stats {
    std::uint64_t updates = 0;        ///< update() calls that computed something.
    std::uint64_t skipped = 0;        ///< update() calls on which nothing had changed.
    std::uint64_t objects_moved = 0;  ///< Updates with at least one moved object.
    std::uint64_t world_light_changes =
        0;                            ///< Updates that re-gathered every object's world light (set_moving_world_light).
    std::size_t pairs_evaluated = 0;  ///< Last update (GPU pass stats).
    std::size_t pairs_culled = 0;
    std::size_t pairs_reused = 0;
    std::size_t static_hidden = 0;    ///< Last update: atlas texels in a moved object's field that do not see it.
    double last_visibility_ms = 0.0;  ///< Last update: their rays against the static world (in last_gpu_ms).
    double last_cpu_ms = 0.0;         ///< Direct light, probes, fits.
    double last_gpu_ms = 0.0;         ///< GPU pass + vertex sums (glFinish-timed).
    std::size_t instances = 0;
    std::size_t vertices = 0;
    std::size_t static_receivers = 0;
    std::size_t field_bytes = 0;  ///< Precomputed data of all models (CPU copies).
    std::size_t gpu_bytes = 0;
    std::string disabled;                  ///< Why the fields turned off (no GPU resources); empty: running.
    float influence_scale_setting = 0.0f;  ///< BrfUpdateSettings::influence_scale as given.
    /// The reach in use: below the setting after reach_narrowings narrowed it to fit the pairs'
    /// Phi in the GPU's buffer limit.
    float influence_scale = 0.0f;
    std::uint64_t reach_narrowings = 0;
  };
  const Stats& stats() const;

 private:
  struct Impl;
  explicit BrfLighting(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
