#pragma once
// The moving lights in the world probes that light dynamic objects (docs/brf.md, "The moving
// lights in the probes"). A PRM entry point is where a moving light first hits the static
// world, so albedo x irradiance x area at it is a VPL of the moving light's first bounce: the
// same kind of emitter the probes were gathered from (world_probes.h). At load, per valid
// probe, the entry points it sees (shadow rays) with kernel and SH weights
// (bake_world_probe_transfer); whenever the PRM's entry irradiance changed (a moving light
// moved, turned, switched, dimmed), the powers are re-projected into probe SH (no ray) that
// BrfLighting adds to the static probes. A frame where no moving light changed does nothing.
// The moving lights' second and later bounces off the world are left out.
// Internal to GISystem.
//   auto light = gi::PrmProbeLight::create(*caster, grid, prm.entries, gi::prm_entry_albedo(statics,
//   prm.entries)).value(); if (light.update(prm_lighting)) brf.set_moving_world_light(light.radiance_sh());

#include <engine/result.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "brf/world_probes.h"

namespace gi {

struct PrmEntryPoint;
struct StaticBakeScene;
class PrmLighting;
class RayCaster;

/// Per entry point, the hemispherical albedo of the static surface it lies on (the material
/// of the triangle a short ray along -normal hits; 0 where none is found, counted in `missed`).
std::vector<glm::vec3> prm_entry_albedo(const StaticBakeScene& statics, std::span<const PrmEntryPoint> entries,
                                        std::size_t* missed = nullptr);

class PrmProbeLight {
 public:
  /// Errors: albedo count other than the entry count, non-finite entry data.
  static engine::Result<PrmProbeLight> create(const RayCaster& static_world, const WorldProbeGrid& grid,
                                              std::span<const PrmEntryPoint> entries, std::vector<glm::vec3> albedo,
                                              unsigned threads = 0);

  /// Re-projects when the PRM's entry irradiance changed since the last call (entry_version);
  /// true then. Errors in the re-projection (non-finite irradiance) leave the last SH and
  /// return false.
  bool update(const PrmLighting& prm);
  /// Re-projects for the given entry irradiance (W/m^2 per entry point). False on a size
  /// mismatch or non-finite values (the last SH is kept).
  bool reproject(std::span<const glm::vec3> entry_irradiance);

  /// Per probe of the grid: the moving lights' first-bounce radiance SH (zeros for invalid probes).
  const std::vector<std::array<glm::vec3, 9>>& radiance_sh() const { return sh_; }

  struct Stats {
    std::uint64_t reprojections = 0;
    double last_ms = 0.0;  ///< Last re-projection (CPU).
    std::size_t transfer_bytes = 0;
    std::size_t transfer_entries = 0;  ///< (probe, visible entry point) pairs.
  };
  const Stats& stats() const { return stats_; }

 private:
  WorldProbeTransfer transfer_;
  std::vector<glm::vec3> albedo_area_;  ///< Per entry point: albedo x area.
  std::vector<std::array<glm::vec3, 9>> sh_;
  std::uint64_t seen_version_ = 0;
  bool seen_any_ = false;
  Stats stats_;
};

}  // namespace gi
