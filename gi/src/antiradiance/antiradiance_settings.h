#pragma once
// The quality knobs of the antiradiance solver (Dachsbacher et al. 2007), one struct so the
// bake, the runtime and the sweep read the same names.
//   gi::AntiradianceSettings s;  s.bins_per_side = 8;  s.residual_tolerance = 1e-3;

#include <cstdint>
#include <string_view>

namespace gi {

/// Which iteration of §2.2 solves eqs. 11-12.
enum class AntiradianceScheme : std::uint8_t {
  Symmetric,   ///< Alternate eq. 13 and eq. 14 (one global pass per iteration; the paper's choice).
  Asymmetric,  ///< Per radiance step (eq. 13), `antiradiance_steps` steps of eq. 14 with L frozen.
};

/// The most pieces per link end a bake may ask for (the sweep's grid and a file's check).
inline constexpr int kMaxLeafLinkPieces = 4096;

struct AntiradianceSettings {
  /// Octahedral cells per side: bins = n^2 (8: 64 bins; the paper uses 128, n = 11 or 12 comes closest).
  int bins_per_side = 8;
  /// Leaves are triangle pieces whose longest edge is at most this (metres).
  float patch_size_m = 0.5f;
  /// Adaptive leaves (issue 37): pieces within near_radius_m of a deforming instance's swept
  /// sphere (its origin, through its farthest vertex), and the deforming instances' own pieces,
  /// are split until their longest edge is at most this (metres); 0: off (patch_size_m
  /// everywhere). A bundle stores the hierarchy, so a load does not read it.
  float near_patch_size_m = 0.0f;
  /// How far from the swept sphere the leaves are near_patch_size_m (metres).
  float near_radius_m = 1.0f;
  /// Leaf-leaf links that fail the oracle (issue 37): each end is split virtually into up to
  /// this many equal-area disc pieces, as many as the oracle asks for at the pair's distance,
  /// each piece pair with its own distance and bin (link_mesh.h); 0: off (the two leaves are
  /// linked regardless, as one disc). Stored in antiradiance.bin (version 3): a load relinks
  /// the deforming elements with it.
  int leaf_link_pieces = 0;
  /// Precise near links (issue 37; the paper's CPU scheme, §3.1: "the precise computation of
  /// exchanges between all pairs of bins in the cone subtended by the sender as seen from the
  /// receiver"): a link with an end in the near set (a deforming instance's element, or a
  /// static element within near_radius_m of a deforming instance's swept sphere) is made from
  /// both ends cut into equal-area pieces (a surface element's own triangle), each piece at
  /// most 1/q of the oracle's solid angle as seen from the other end (the sender at least q
  /// pieces), every piece pair adding to the bin of its own direction at its own distance
  /// (link_mesh.h). q = this; 0: off (near links are made as every other link). Not stored in
  /// antiradiance.bin, and a loaded hierarchy has no triangles: the sweep's setting only
  /// (docs/antiradiance.md "Issue 37: precise near links": it did not pay off).
  int near_link_samples = 0;
  /// Precise near links: at most this many pieces per end (the touching pairs, a door's edge
  /// against its frame, run into it; a link sums up to its square of piece pairs).
  int near_link_max_pieces = 256;
  /// Static triangles within this distance of the deforming region's swept bounds exchange
  /// light with it (metres).
  float exchange_radius_m = 8.0f;
  /// The oracle links two elements when each one's solid angle seen from the other is at
  /// most oracle_scale x the smallest bin solid angle (1: the paper's rule).
  float oracle_scale = 1.0f;
  /// The iteration budget (global + push + local + pull each; asymmetric: radiance steps):
  /// the solve stops at the residual tolerance, at the latest after this many iterations
  /// (then it reports budget_exhausted, antiradiance_solver.h).
  int iterations = 64;
  /// Asymmetric: antiradiance steps (eq. 14) before each radiance step (eq. 13).
  int antiradiance_steps = 4;
  AntiradianceScheme scheme = AntiradianceScheme::Symmetric;
  /// Converged when the relative residual of an iteration (sum |Delta I_ex| / sum |I_ex|: the
  /// change relative to the region's exitant energy) drops below it; 0: always run
  /// `iterations` (a fixed, unconverged count).
  double residual_tolerance = 1e-3;
  /// A door move's solve starts from the previous pose's solution (runtime only, not stored
  /// in a bundle: the bake's baseline always starts from the direct light); false: every
  /// solve starts from the direct light, as before issue 37's warm start.
  bool warm_start = true;
  /// A warm-started solve is converged when, besides residual_tolerance, its residual sum has
  /// dropped by this factor from its first iteration's (the door's change converged by about
  /// that factor; antiradiance_solver.h).
  double warm_tolerance = 0.03;
  /// Symmetric: fall back to the asymmetric scheme (restarted from the direct light) when
  /// the residual grew this many iterations in a row, or the intensities exceed the bound.
  int growth_limit = 2;
  /// Stratified points per area light / emissive triangle for the direct light.
  int area_light_samples = 16;
  std::uint64_t seed = 1;
  /// Near-door visibility at run time (issue 37; NearDoorVisibility, near_door_visibility.h):
  /// the leaves within near_visibility_radius_m of a deforming instance's reach (and its own
  /// leaves) gather their light with ray-traced visibility from every leaf, the others keep
  /// the antiradiance solve. The runtime computes the baked pose's couplings at load and
  /// updates them on every door move (AntiradianceLighting). Stored in antiradiance.bin
  /// (version 4, with the elements' triangles the rays need).
  bool near_visibility = false;
  /// Leaves whose bounding sphere comes this close to the instance's reach are receivers (m;
  /// NearDoorVisibilitySettings::radius_m).
  float near_visibility_radius_m = 1.0f;
  /// Beyond the radius, more receivers nearest the instance first while their rows fit this
  /// many bytes per deforming instance (NearDoorVisibilitySettings::budget_bytes; 0: the radius
  /// alone).
  std::uint64_t near_visibility_budget_bytes = 0;
  /// Point pairs per leaf pair (NearDoorVisibilitySettings::point_pairs; 1..64: the kept
  /// visibility holds 64 bits per pair). 4 scored as 16 on the corridor (0.1033 / 0.1032 of
  /// the level, docs/antiradiance.md) at a quarter of the rays.
  int near_visibility_point_pairs = 4;
};

/// The settings gi-bake bakes a preset at (and the planner estimates; issue 37, measured by
/// gi-sweep on the corridor, docs/antiradiance.md "Issue 37: the presets"): 0.8 m leaves at
/// every preset (0.6 / 0.4 m were worse at every bin count and cost 2-4x), the leaf links
/// split to meet the oracle (at most 64 pieces per end: better at the same cost), and
/// 64 / 144 / 324 bins at preview / medium / high (the bins buy the accuracy, at 2.4x / ~4x
/// the preview's door move and file; 256 bins scored worse than 144 at the door's fourth angle,
/// and 400 bins put the demo level's 17.3 M static links at 138 MB, above llvmpipe's 128 MiB
/// SSBO limit for the GPU pass). Near-door visibility at medium and high, its set grown to a
/// budget of 64 / 128 MiB of rows (on the corridor every leaf: the change's error 0.050 of the
/// level with the noise removed against medium's 0.182 alone and 0.087 for the 1 m radius, at
/// ~1.4x the plain door move; docs/antiradiance.md "A near set as large as its budget"), not at
/// preview (its load work and memory on a preview's budget).
inline AntiradianceSettings antiradiance_preset(std::string_view preset) {
  AntiradianceSettings s;
  s.patch_size_m = 0.8f;
  s.leaf_link_pieces = 64;
  s.bins_per_side = preset == "high" ? 18 : preset == "medium" ? 12 : 8;
  s.near_visibility = preset == "high" || preset == "medium";
  s.near_visibility_budget_bytes = preset == "high" ? 128ull << 20 : preset == "medium" ? 64ull << 20 : 0;
  return s;
}

}  // namespace gi
