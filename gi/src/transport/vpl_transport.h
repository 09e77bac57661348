#pragma once
// Light transport among VPLs (Schärfig et al. 2016, §3.2-3.3): direct light from the point
// emitters into every VPL's patch, then progressive refinement by shooting.
//   std::vector<glm::vec3> direct = gi::direct_to_vpls(vpls, emitters, caster, pool);
//   gi::VplSolution s = gi::propagate(vpls, direct, caster, pool, {.bounces = 5}).value();

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <gi/progress.h>

#include "core/color.h"
#include "core/thread_pool.h"
#include "raytrace/ray_caster.h"
#include "transport/point_emitters.h"
#include "transport/vpl_set.h"

namespace gi {

/// Direct irradiance I_j of every VPL (eq. 5-6): the area-weighted mean over its sample
/// points of each emitter's (regularized) irradiance times the sample's visibility, so the
/// visibility fraction V_ij of eq. 6 is taken per sample point. Each punctual light's share
/// is then rescaled so the patches receive the flux it really sends onto the scene (traced
/// over 4096 directions): sample points cannot resolve the flux of a light touching a
/// surface. `rays` counts the rays cast.
std::vector<glm::vec3> direct_to_vpls(const VplSet& vpls, const std::vector<PointEmitter>& emitters,
                                      const RayCaster& caster, ThreadPool& pool, std::uint64_t* rays = nullptr);

struct PropagationSettings {
  int bounces = 5;                                       ///< 1: no shooting; b: b - 1 generations.
  float unshot_threshold = 1e-4f;                        ///< Relative to the largest VPL power after direct light.
  std::size_t row_cache_bytes = std::size_t{512} << 20;  ///< Form-factor rows kept for later generations.
  int reach_rays = 256;  ///< Cosine rays per shooter estimating how much of its light hits the scene.
  std::uint64_t seed = 1;
  ProgressCallback progress;  ///< Fraction of the shots of the current generation.
};

struct VplSolution {
  std::vector<glm::vec3> irradiance;  ///< Total irradiance I_j at each VPL (direct + propagated).
  std::size_t shots = 0;
  std::uint64_t rays = 0;
};

/// Progressive refinement (eq. 7-8), one generation per bounce so the bounce count is exact:
/// in generation g the VPLs are taken from a priority queue on unshot power
/// dE_i = rho_i A_i dI_i (eq. 7, with the patch area A_i), largest first; each shoots
/// dE_i F'_ij into every VPL j's next-generation unshot irradiance, where F'_ij is the
/// symmetric scaled form factor of §3.3 evaluated at j's sample points (cos cos / (pi d^2 +
/// A_i + a_k) times visibility; point_emitters.h explains the regularization). A generation
/// ends when the queue's largest unshot power falls below the threshold.
/// Energy: the discrete form factors of a row sum to slightly less than the fraction of the
/// shooter's light that really lands on the scene (the near-field regularization, patches
/// seen at grazing angles). Each row is therefore rescaled so that sum_j A_j F'_ij equals
/// that fraction, estimated with `reach_rays` cosine-distributed rays from the shooter's
/// sample points (1 exactly in a closed room), as classic radiosity normalizes form-factor
/// rows; closed rooms then keep the geometric series 1 / (1 - rho) (tested). Deterministic: each
/// shot updates the receivers in parallel, shots in queue order. Errors: cancelled.
engine::Result<VplSolution> propagate(const VplSet& vpls, const std::vector<glm::vec3>& direct, const RayCaster& caster,
                                      ThreadPool& pool, const PropagationSettings& settings);

}  // namespace gi
