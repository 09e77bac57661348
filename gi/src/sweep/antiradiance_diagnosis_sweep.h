#pragma once
// The diagnosis runs of the antiradiance sweep (issue 37, docs/antiradiance.md "what limits
// the change"): `solve=off` (the projection floor), `solve=exact` (the visibility-exact solver on
// the method's leaves) and `near_visibility` (explicit visibility near the door on top of the
// method's solve), with their knobs.
//   if (ctx.knobs.text("solve") == "exact") return run_exact_transport(ctx, door, settings);

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "antiradiance/antiradiance_region.h"
#include "antiradiance/near_door_visibility.h"
#include "sweep/antiradiance_door_scoring.h"
#include "sweep/knob_spec.h"

namespace gi::antiradiance_sweep {

/// The knobs of the diagnosis: exact_pairs, exact_bounces, near_visibility, near_budget_mb, exact_adaptive,
/// exact_noise, exact_reuse, exact_seed.
std::vector<KnobSpec> exact_knobs();

// `--knob near_visibility=on` (issue 37, off by default): the leaves near the door (its own,
// and the static ones within near_radius of its swept sphere) take their indirect light from
// every leaf through ray-traced visibility (form factors, ExactLeafTransport) instead of the
// antiradiance links: radiance only, every link of such a receiver tested; the other leaves
// keep the antiradiance solve's (NearDoorVisibility). Its change is this hybrid now minus at
// the baked pose.
struct NearVisibility {
  std::optional<NearDoorVisibility> near;
  std::size_t receivers = 0;
  double bake_ms = 0.0, move_ms = 0.0, rays = 0.0, pairs = 0.0;
  double update_ms = 0.0;   // of move_ms: the couplings' update (the rest: the receivers' solve)
  double iterations = 0.0;  // the receivers' solve, mean per move

  engine::Status init(const RunContext& ctx, const DoorSetup& d, AntiradianceRegion& region) {
    NearDoorVisibilitySettings ns;
    ns.radius_m = region.settings().near_radius_m;
    ns.budget_bytes = static_cast<std::size_t>(ctx.knobs.integer("near_budget_mb")) << 20;
    ns.point_pairs = static_cast<int>(ctx.knobs.integer("exact_pairs"));
    ns.seed = static_cast<std::uint64_t>(ctx.knobs.integer("exact_seed"));
    ns.reuse_visibility = ctx.knobs.text("exact_reuse") == "on" && ns.point_pairs <= 64;
    const auto t0 = Clock::now();
    region.update(false);  // the direct light at the baked pose
    auto n = NearDoorVisibility::create(d.input, region, d.door, ns);
    if (!n) return n.error();
    near.emplace(std::move(n).value());
    bake_ms = ms_since(t0);
    receivers = near->receivers();
    return {};
  }
  // After the region moved the door to `m` and solved: the hybrid's change per leaf.
  std::vector<glm::vec3> delta(const DoorSetup& d, const AntiradianceRegion& region, const glm::mat4& m,
                               std::size_t moves) {
    const auto t0 = Clock::now();
    std::vector<glm::vec3> e = near->move(region, d.door, m);
    move_ms += ms_since(t0) / static_cast<double>(moves);
    update_ms += near->last_update_ms() / static_cast<double>(moves);
    iterations += static_cast<double>(near->last_iterations()) / static_cast<double>(moves);
    rays += static_cast<double>(near->last_rays()) / static_cast<double>(moves);
    pairs += static_cast<double>(near->last_pairs()) / static_cast<double>(moves);
    for (std::size_t l = 0; l < e.size(); ++l) e[l] -= near->baseline()[l];
    return e;
  }
};

/// `--knob solve=off`: the leaves only; the field is their projection floor.
engine::Result<MethodOutput> run_projection_floor(const RunContext& ctx, const DoorSetup& d,
                                                  const AntiradianceSettings& s);
/// `--knob solve=off` with `ref_pair`: the projection floor with the references' noise removed
/// (SplitTruthFloor: the mean of the two references' changes through the leaves, less the
/// floor of their half difference), as `split_floor_*` extras in split_rel_rmse's units, and
/// per angle in split_change_nrmse_swing_*'s.
engine::Result<std::vector<std::pair<std::string, double>>> split_floor_extras(const DoorSetup& d,
                                                                               const AntiradianceSettings& s,
                                                                               const RgbField& a, const RgbField& b);
/// `--knob solve=exact`: the visibility-exact solver on the method's leaves, scored like it.
engine::Result<MethodOutput> run_exact_transport(const RunContext& ctx, const DoorSetup& d,
                                                 const AntiradianceSettings& s);

}  // namespace gi::antiradiance_sweep
