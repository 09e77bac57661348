#pragma once
// The static world as a light source for dynamic objects: a regular grid of irradiance
// probes, each holding the radiance arriving from the static world's baked light as 3-band
// spherical harmonics (RGB). A dynamic vertex's world light is the probes' radiance,
// interpolated trilinearly at its position, dotted with its normal's clamped-cosine lobe.
//   auto grid = gi::bake_world_probes(*static_caster, atlas.vpls, atlas.vpl_power, {.spacing_m = 1.0f}).value();
//   glm::vec3 e = grid.irradiance(world_position, world_normal);   // W/m^2
//
// The radiance comes from the light atlas's VPL solution (Schärfig 2016): VPL i leaving
// power Phi_i from its patch (area A_i, normal n_i) sends a probe at distance d, direction
// w (probe to VPL), the radiance-times-solid-angle Phi_i cos_i / (pi d^2 + A_i) (the
// regularized Lambertian kernel of light_atlas/point_emitters.h), projected on Y(w), with
// one shadow ray against the static world. It is what the atlas's final shooting sends into
// texels, so the dynamic objects see the same world light as the static ones: direct light
// reflected once plus the atlas's bounces, static lights only (moving lights' bounce off
// the world, PRM's domain, is not in the probes).
//
// One probe per grid cell, at its centre (none on the faces of the VPLs' box: a room's walls,
// floor and ceiling). Probes that see the back of a surface (behind a wall, inside an object)
// or no VPL get weight 0 and interpolation renormalizes over the others, so walls do not leak
// darkness into rooms. A point whose 8 probes are
// all invalid gets no world light.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>

#include "transport/vpl_set.h"

namespace gi {

class RayCaster;

struct WorldProbeSettings {
  float spacing_m = 1.0f;  ///< Grid spacing.
  int max_probes = 65536;  ///< The spacing grows until the grid fits.
  unsigned threads = 0;    ///< 0: all hardware threads. The result does not depend on it.
};

struct WorldProbeGrid {
  glm::vec3 origin{0.0f};  ///< Probe (0, 0, 0).
  float spacing = 1.0f;
  glm::ivec3 dims{0};
  /// Per probe (x fastest, then y, then z): 9 SH coefficients per channel, radiance_sh[p][k].
  std::vector<std::array<glm::vec3, 9>> radiance_sh;
  std::vector<std::uint8_t> valid;  ///< Probe sees at least one VPL.

  std::size_t probe_count() const { return radiance_sh.size(); }
  std::size_t bytes() const { return radiance_sh.size() * sizeof(radiance_sh[0]) + valid.size(); }
  /// World light (W/m^2) at world point p with unit normal n; 0 outside the grid's reach.
  glm::vec3 irradiance(const glm::vec3& p, const glm::vec3& n) const;
  /// The radiance SH interpolated at p (over the valid probes); false (and zeros) where no
  /// valid probe reaches. For lobes other than the cosine (a glossy vertex's g_k cos).
  bool radiance(const glm::vec3& p, std::array<glm::vec3, 9>& out) const;
};

/// Probes over the bounding box of the VPLs, at the centres of its cells. Errors: VPL arrays of
/// different sizes, non-finite values, spacing not positive.
engine::Result<WorldProbeGrid> bake_world_probes(const RayCaster& static_world, const VplSet& vpls,
                                                 std::span<const glm::vec3> vpl_power,
                                                 const WorldProbeSettings& settings);

/// The probes' light from other emitters than the atlas's VPLs, whose power changes at run
/// time (the PRM's entry points lit by moving lights: albedo x irradiance x area is the first
/// bounce's power, docs/brf.md): a sparse linear map from emitter power to each valid probe's
/// radiance SH, with the same regularized kernel and shadow rays as bake_world_probes. Built
/// once; re-projecting new powers casts no ray.
//   auto t = gi::bake_world_probe_transfer(*caster, grid, pos, nrm, area).value();
//   auto sh = gi::reproject_world_probes(t, power).value();   // per probe, add to grid.radiance_sh
struct WorldProbeTransfer {
  std::vector<std::uint32_t> first;               ///< probe_count + 1: probe p's entries [first[p], first[p + 1]).
  std::vector<std::uint32_t> emitter;             ///< Per entry: the emitter it sees.
  std::vector<std::array<float, 9>> coefficient;  ///< Per entry: cos / (pi d^2 + A) x Y_j(probe -> emitter).
  std::size_t emitter_count = 0;
  std::size_t bytes() const {
    return first.size() * sizeof(first[0]) + emitter.size() * sizeof(emitter[0]) +
           coefficient.size() * sizeof(coefficient[0]);
  }
};

/// For every valid probe of `grid`, the emitters (position, unit normal, area) it sees past the
/// static world. Errors: arrays of different sizes, non-finite values.
engine::Result<WorldProbeTransfer> bake_world_probe_transfer(const RayCaster& static_world, const WorldProbeGrid& grid,
                                                             std::span<const glm::vec3> position,
                                                             std::span<const glm::vec3> normal,
                                                             std::span<const float> area_m2, unsigned threads = 0);

/// Radiance SH per probe (zeros for invalid probes) from the emitters' power (W, RGB).
/// Errors: a power count other than the transfer's emitter count, non-finite power.
engine::Result<std::vector<std::array<glm::vec3, 9>>> reproject_world_probes(const WorldProbeTransfer& transfer,
                                                                             std::span<const glm::vec3> power);

}  // namespace gi
