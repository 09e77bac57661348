#pragma once
// The runtime side of PRM (Szécsi et al. 2006, §4 eq. 4 and §5.2), CPU reference: weights of
// entry points under the current lights, cluster weights (the mean of the members'), the K
// heaviest clusters, and the weighted sum of their panes into an irradiance atlas. The GPU
// pass (prm_gpu_pass.h) computes the same sum; tests hold the two together.
//   auto e = gi::entry_irradiance(prm, emitters, caster);
//   auto picked = gi::select_clusters(gi::cluster_weights(prm, e), 32);
//   std::vector<glm::vec3> atlas = gi::sum_panes(prm, picked);

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "prm/prm.h"
#include "raytrace/ray_caster.h"
#include "transport/point_emitters.h"

namespace gi {

class ThreadPool;

/// Irradiance (W/m^2, RGB) at every entry point from `lights` with shadow rays (eq. 4: the
/// emission x visibility x cos / (d^2 + A/pi) form, A the entry point's area, so a light
/// touching a surface stays bounded; point lights are I cos / (d^2 + A/pi)). A punctual
/// light's weights are rescaled to the flux it sends onto the scene (64^2 traced
/// directions); when the entry points see less than a quarter of it (a light touching a
/// surface lights only millimetres), the traced hits are deposited on their nearest entry
/// points instead. `pool` (optional) traces the flux check's rays over its threads: the
/// same result bit for bit.
std::vector<glm::vec3> entry_irradiance(const Prm& prm, std::span<const PointEmitter> lights, const RayCaster& caster,
                                        ThreadPool* pool = nullptr);

/// Weight of every cluster: the mean irradiance of its members (§5.1).
std::vector<glm::vec3> cluster_weights(const Prm& prm, std::span<const glm::vec3> entry_irradiance);

struct ClusterWeight {
  std::uint32_t cluster = 0;
  glm::vec3 weight{0.0f};
};

/// The `k` clusters of largest weight (luminance), heaviest first; clusters of zero weight
/// are never selected (k <= 0: all non-zero clusters).
std::vector<ClusterWeight> select_clusters(std::span<const glm::vec3> weights, int k);

/// The whole per-light-change step: point emitters of `lights` (16 points per area light),
/// entry irradiance, cluster weights and the `k` heaviest clusters (k <= 0: all).
std::vector<ClusterWeight> relight_clusters(const Prm& prm, std::span<const ReferenceLight> lights,
                                            const RayCaster& caster, int k);

/// sum over `selected` of weight x pane, written to an atlas of width x height texels (0
/// outside the panes' texels); with coarse panes (prm.atlas), that sum read at the light
/// atlas's texels (atlas_width() x atlas_height(), 0 outside its valid texels) by the
/// upsampler, once. The CPU twin of PrmGpuPass::run.
std::vector<glm::vec3> sum_panes(const Prm& prm, std::span<const ClusterWeight> selected);

}  // namespace gi
