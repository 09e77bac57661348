#pragma once
// Directional light maps (Hey and Purgathofer 2002, "Real-time rendering of globally
// illuminated soft glossy scenes with directional light maps"): for the glossy static
// surfaces, the spatially and directionally varying indirect light they receive, stored per
// light-atlas texel for one global set Omega of incoming directions.
//   gi::Dlm dlm = gi::bake_dlm(input, gi::dlm_preset("medium").value()).value();
//   // dlm.radiance[(k * dlm.texels.size() + i) * 3 + ch]: mean incoming radiance from bin k
//
// Bake (paper §3.1, deviations in docs/dlm.md):
//   1. Omega: N directions of a spherical Fibonacci lattice (near-uniform; the paper warps
//      random points [Shi92]). Bin k = the directions nearest psi_k (the paper's rule). At a
//      texel of normal n the bins whose cell reaches above the horizon hold light, also a psi
//      just below it (its cell's sliver above): light at the horizon stays in bins at the horizon.
//   2. Photons from the static lights and emissive static surfaces (transport/point_emitters),
//      chosen in proportion to their power, each from its own random stream (seed, photon).
//      A path bounces diffusely with the hemispherical albedo of the glTF BRDF (Russian
//      roulette), as the light atlas folds every surface. The first hit is direct light (the
//      renderer's) and is not stored: every later hit on a glossy texel splats the photon's
//      power into the bin nearest its incoming direction, with a pyramidal (tent) kernel of
//      `splat_radius_texels` over the texels of the hit's chart.
//   3. The splatted irradiance of bin k, E_k (W/m^2 over the texel's area), becomes the bin's
//      mean radiance L_k = E_k / C_k(n), C_k(n) = integral over the bin's directions above the horizon
//      of n.w dw (by quadrature over a fine Fibonacci set): uniform incoming radiance L gives
//      L_k = L in every bin. So the renderer integrates the glTF lobe against L_k
//      (engine/directional_radiance.h). A bin whose C_k is small cannot hold more than the
//      photons' flux over C_k: finite, and bounded by the lights' flux (tested).
//   4. Each bin's map is dilated like the light atlas into the chart gutters.
// Glossy texels: those whose owning triangle's material has roughness in [glossy_roughness_min,
// glossy_roughness) (the planner's range, per triangle). Bit-identical for any thread count: photons are traced
// in fixed batches whose deposits are summed in photon order.

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/progress.h>

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>
#include <glm/glm.hpp>

#include "uv/atlas_layout.h"

namespace gi {

struct DlmSettings {
  float texels_per_metre = 16.0f;     ///< Atlas density; the layout is the light atlas's (same preset, same uv1).
  int directions = 32;                ///< N = |Omega|, 8..256.
  std::uint64_t photons = 1'000'000;  ///< Photon paths shot from the lights.
  float splat_radius_texels = 1.5f;   ///< Tent kernel radius (the paper's pyramidal splats are 1.5 texels wide).
  float glossy_roughness = 0.8f;      ///< Texels of materials with roughness below this get maps (PlanOptions)
  float glossy_roughness_min = 0.0f;  ///< ... and at or above this (sharper ones are the reflection probes').
  int max_bounces = 16;               ///< Safety stop of a photon path (Russian roulette ends it first).
  int area_light_samples = 16;        ///< Point emitters per area light or emissive triangle.
  /// Bins in each texel's tangent frame: `directions` on the hemisphere about the texel's
  /// normal (dlm_hemisphere_directions) instead of one global set, so a texel gets all N cells
  /// above its horizon (docs/dlm.md, "The corridor's grazing band"). The bundle keeps the flag
  /// (dlm.bin version 3) and the renderer turns each lobe sample into the texel's frame
  /// (engine::directional_tangent_frame of the vertex normal, IndirectLightFrame::directional_tangent_frame).
  bool tangent_frame_bins = false;
  /// Tangent-frame bins only: the hemisphere set's z raised to this power (1: equal areas; 2:
  /// the cells near the horizon, where a grazing lobe reads, about half as tall). Not in dlm.bin:
  /// the file holds the directions themselves, which is all the renderer reads.
  double horizon_warp = 1.0;
  std::uint64_t seed = 1;
  unsigned threads = 0;       ///< 0: all hardware threads. The result does not depend on it.
  ProgressCallback progress;  ///< Fraction done; false cancels.
};

struct DlmStats {
  std::uint64_t photons = 0;
  std::uint64_t rays = 0;
  std::uint64_t deposits = 0;       ///< Photon hits (after a bounce) splatted into a glossy texel.
  std::uint64_t lost_deposits = 0;  ///< Hits on a glossy triangle that found no texel of its chart.
  double emitted_watts = 0.0;       ///< Total power of the emitters (luminance).
  std::size_t glossy_texels = 0;    ///< Texels covered by glossy triangles.
  double trace_seconds = 0.0;
  double total_seconds = 0.0;
};

/// A baked set of directional light maps over the light-atlas layout.
struct Dlm {
  AtlasLayout layout;
  int width = 0;
  int height = 0;
  /// Omega: N unit vectors; with settings.tangent_frame_bins, N on the hemisphere z > 0 of a
  /// texel's tangent frame (dlm_texel_directions turns them to a normal).
  std::vector<glm::vec3> directions;
  /// Atlas texel index (y * width + x) of each stored element, ascending: the glossy texels
  /// and the gutter texels dilation filled next to them.
  std::vector<std::uint32_t> texels;
  /// Bin k, element i, channel ch at radiance[(k * texels.size() + i) * 3 + ch]: mean
  /// incoming indirect radiance (W/(m^2 sr)) from the directions of bin k. Zero in bins
  /// whose cell lies wholly below the texel's horizon.
  std::vector<float> radiance;
  DlmSettings settings;
  DlmStats stats;

  std::size_t texel_count() const { return texels.size(); }
};

/// preview / medium / high: the density is the light atlas preset's of that name.
engine::Result<DlmSettings> dlm_preset(std::string_view name);

/// The N directions of Omega (spherical Fibonacci lattice), deterministic.
std::vector<glm::vec3> dlm_directions(int count);

/// N directions on the hemisphere z > 0 (equal-area spherical Fibonacci), for tangent-frame bins;
/// with `horizon_warp` w > 1 the lattice's z is raised to the power w (denser cells towards the
/// horizon). Sorted by decreasing z, as the renderer's search needs.
std::vector<glm::vec3> dlm_hemisphere_directions(int count, double horizon_warp = 1.0);

/// The bins' directions in world space at a texel of unit normal `n`: the global set, or
/// with tangent-frame bins the hemisphere set turned to n (engine::directional_tangent_frame(n):
/// x, y, n, the renderer's frame).
std::vector<glm::vec3> dlm_texel_directions(const Dlm& dlm, const glm::vec3& n);

/// The bin of incoming direction `w`: the nearest direction psi_k (the paper's rule, at every
/// normal; engine::directional_bin_of is the renderer's twin).
std::uint32_t dlm_bin(std::span<const glm::vec3> directions, const glm::vec3& w);

/// C_k(n) for every bin: integral over the hemisphere of n of n.w, split by dlm_bin(w)
/// (`quadrature`-point Fibonacci quadrature over the sphere). Sums to ~pi.
std::vector<float> dlm_bin_cosine_weights(std::span<const glm::vec3> directions, const glm::vec3& n,
                                          int quadrature = 4096);

/// Quadrature points of C_k for tangent-frame bins: their C_k are the same at every normal,
/// computed once, so finely (4096 points left ~16 per bin of 128 and few near the horizon,
/// where a grazing lobe reads: docs/dlm.md, "Tangent-frame bins in the renderer").
inline constexpr int kDlmTangentQuadrature = 1 << 18;

/// Bakes the directional light maps of the glossy Static instances of `input` under its
/// static lights and emissive static surfaces. Errors: settings out of range, invalid input,
/// no static geometry, cancelled. No glossy texel gives an empty (valid) Dlm.
engine::Result<Dlm> bake_dlm(const BakeInput& input, const DlmSettings& settings);

}  // namespace gi
