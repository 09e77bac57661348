#pragma once
// The iteration of Dachsbacher et al. 2007, §2.2, over either twin of the passes
// (antiradiance_passes.h):
//   symmetric  (eqs. 13 and 14 alternated): per iteration global, push, local(K and J), pull;
//   asymmetric (eq. 13 after eq. 14 converged for frozen L): per iteration
//              `antiradiance_steps` x (global, push, local(J), pull), then global, push,
//              local(K), pull.
// The symmetric scheme has no convergence proof (§2.2: U can create energy); DESIGN.md §3 asks
// to detect divergence and fall back. We watch the residual sum |Delta I_ex|: when it exceeds
// both the previous iteration's and the first iteration's residual `growth_limit` iterations
// in a row (early oscillation, Fig. 2, is allowed), or anything becomes non-finite, the solve
// restarts from the direct light with the asymmetric scheme, which converges like classical
// light transport when the discrete operators do. So does a symmetric iteration that stalls
// (with a tolerance set: 8 iterations, after the first 16, that do not halve the residual
// sum). The discrete operators need not converge: with elements coarse against the spacing of
// many layers (a stack of plates) the discretized unoccluded transport creates energy and the
// asymmetric scheme grows too. The same growth test stops it, and a last guard bounds the
// result by energy: the indirect flux sum_leaves a E cannot exceed what the direct light
// reflects, F_rd = sum a albedo E_direct, times 1 / (1 - albedo_max) (every further bounce
// keeps at most albedo_max of it); above that (or non-finite) the output is scaled down to the
// bound (output_scale).
//
// The solve runs to the residual tolerance (settings.residual_tolerance: sum |Delta I_ex| /
// sum |I_ex| of the last iteration, the change relative to the region's exitant energy),
// within a budget of settings.iterations; a solve that used the whole budget without reaching
// it says so (budget_exhausted), and the callers warn and flag it in their stats. The bake's
// baseline and the runtime solve the same way, so both stop within the tolerance of the same
// fixed point (a cold start from the direct light: at the baked pose the two solves are the
// same computation and the change is exactly 0).
//   gi::AntiradianceSolveReport r = gi::run_antiradiance(passes, direct, settings, bound);

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "antiradiance/antiradiance_passes.h"
#include "antiradiance/antiradiance_settings.h"

namespace gi {

struct AntiradianceSolveReport {
  AntiradianceScheme scheme = AntiradianceScheme::Symmetric;  ///< The scheme that produced the result.
  bool warm = false;              ///< It started from the last solve's tables (and did not fall back).
  bool fell_back = false;         ///< The symmetric iteration grew (or stalled) and was replaced.
  bool stalled = false;           ///< ... because it stalled: 8 iterations did not halve its residual (after 16).
  int iterations = 0;             ///< Iterations (radiance steps) of the final scheme.
  int passes = 0;                 ///< Global passes run in all (including a discarded symmetric run).
  std::vector<double> residuals;  ///< Relative residual after each iteration of the final scheme.
  std::vector<double> changes;  ///< Absolute residual sum |Delta I_ex| (W/sr) of the symmetric run, fallen back or not.
  bool diverged = false;        ///< The asymmetric scheme grew too and was stopped.
  bool converged = false;       ///< The relative residual dropped below the tolerance.
  /// The budget (settings.iterations) ran out before the tolerance was reached (and the
  /// solve did not diverge); never with a tolerance of 0.
  bool budget_exhausted = false;
  double residual = 0.0;       ///< Relative residual of the last iteration (0: no iteration).
  double indirect_flux = 0.0;  ///< sum over leaves of area x |E| (W, first channel summed over RGB).
  double flux_bound = 0.0;     ///< The energy bound it was checked against (W).
  /// Multiply passes.irradiance() by this: 1, or what brings the flux down to the bound
  /// (0 when the result was not finite).
  float output_scale = 1.0f;
};

/// The energy bound of a region's indirect light (W): sum over leaves of area x albedo x
/// E_direct (RGB summed) / (1 - min(albedo_max, 0.999)).
double indirect_flux_bound(const ElementHierarchy& h, std::span<const glm::vec3> direct);

/// Where a solve starts.
enum class AntiradianceStart : std::uint8_t {
  Cold,  ///< From the direct light (passes.reset): the bake's baseline, a region's first solve.
  Warm,  ///< From the passes' last solution (passes.warm_start): a door moved since.
};

/// Runs the schedule on `passes` from `direct` (W/m^2 per leaf); the result is
/// passes.irradiance(). A warm start iterates from the passes' tables (precondition: they
/// hold a solve of the same hierarchy and links' layout); a fallback after growth or a stall
/// restarts cold, as a cold solve does.
AntiradianceSolveReport run_antiradiance(AntiradiancePasses& passes, std::span<const glm::vec3> direct,
                                         const AntiradianceSettings& settings, const ElementHierarchy& h,
                                         AntiradianceStart start = AntiradianceStart::Cold);

}  // namespace gi
