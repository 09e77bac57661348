#pragma once
// Final gather into the light atlas: multi-bounce diffuse indirect irradiance estimated at
// every texel by rays from the texel itself, reading the light that the atlas's own texels
// reflect. It replaces the VPL final shooting (light_atlas.h step 4, texels x VPLs shadow
// rays) where that is too slow for its error, and it has no near-field singularity: a texel
// next to a concave edge reads the wall beside it where its rays hit it.
//   gi::TexelGatherResult g = gi::gather_atlas(bake_scene, layout, {.gather_rays = 256}, pool).value();
//
// Steps:
//   1. Direct irradiance E_d at every texel: punctual lights with one shadow ray, area
//      lights and emissive triangles with `direct_samples` stratified samples (light
//      sampling, unbiased); the sky from the rays of steps 2 and 3 that escape.
//   2. Kept-ray solve: `solve_rays` cosine-distributed, stratified rays per texel; the texel
//      each ray lands on is kept, so every bounce after the first costs a lookup, not a ray.
//      Jacobi iteration E_i+1 = T(E_d + E_i), T the kept rays' mean of the reflected
//      rho (E_d + E_i) of the texels they hit, until a bounce adds less than 1e-4 of the
//      total or after `bounces` iterations.
//   3. Final gather: `gather_rays` fresh stratified rays per texel read rho (E_d + E) of the
//      dilated atlas bilinearly where they hit; the result is averaged with step 2's, each
//      weighted by its ray count (both estimate the same T(E_d + E)). With `emitter_rays`,
//      that many more rays go to points drawn on the bright texels (texel_emitters.h), and
//      both kinds of fresh rays are weighted by the balance heuristic (unbiased).
//   4. Optional guided denoiser (`denoise_passes`, atlas_denoise.h: edge-avoiding a-trous
//      guided by the normals, the planes and step 3's per-texel variance), then the
//      optional edge-aware filter in world space: texels within `filter_radius_texels` on
//      the same plane (normals within ~18 degrees, plane distance below half a texel),
//      across chart borders, Gaussian-weighted.
// Surfaces reflect as diffuse with the glTF BRDF's hemispherical albedo (as the VPLs do).
// Back faces of one-sided surfaces are black; rays that escape see the sky (direct light).
// The direct light comes out in two parts: what the renderer draws live (the static lights,
// and the emissive triangles that stand for an area light), and what only the bake has
// (the sky, shadowed by the level, and emissive surfaces no light stands for: `baked_direct`,
// which the atlas always holds; docs/scene-format.md, "What is baked and what is drawn live").
// Deterministic for any thread count: every texel's random numbers come from (seed, texel).

#include <engine/result.h>
#include <gi/progress.h>

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "core/thread_pool.h"
#include "core/work_shard.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace gi {

struct TexelGatherSettings {
  int direct_samples = 16;  ///< Samples per texel on each area light and on the emitters (>= 1).
  int solve_rays = 64;      ///< Kept rays per texel, iterated for all bounces (>= 1).
  int gather_rays = 128;    ///< Fresh final-gather rays per texel (0: the solve alone).
  /// Fresh emitter-sampled rays per texel in step 3 (0: none): aimed at points drawn on the
  /// texels that reflect the most light towards this one (texel_emitters.h), combined with
  /// the cosine rays by multiple importance sampling (balance heuristic).
  int emitter_rays = 0;
  int bounces = 64;                   ///< Most iterations of the kept-ray solve (indirect bounces).
  float filter_radius_texels = 0.0f;  ///< World-space filter radius in texels (0: none).
  /// Step 4's guided denoiser (atlas_denoise.h): a-trous passes over `indirect` and
  /// `baked_direct`, guided by normals, planes and the gather's per-texel variance (0: none).
  int denoise_passes = 0;
  float denoise_sigma = 2.0f;  ///< The denoiser's value weight, in standard deviations.
  /// The denoiser's outlier clamp before its passes (DenoiseSettings::outlier_sigmas): a
  /// texel at most its co-planar neighbours' mean + this many standard deviations (0: off).
  float denoise_outlier_sigmas = 0.0f;
  /// The denoiser's local linear fit (DenoiseSettings::slope_ridge; negative: local mean).
  float denoise_slope_ridge = -1.0f;
  /// The source filter's (`source_filter_radius_texels`) local linear fit, its slopes' ridge
  /// (texel_filter.h; negative: the Gaussian mean).
  float source_filter_slope_ridge = -1.0f;
  /// Step 3's reads where a fresh ray lands: which lights' direct light it takes at the landing
  /// point itself (one shadow ray per light and landing) rather than from the texels, which
  /// then give only the rest. `Edges` (the default): every light's, only across shadow edges
  /// (read_landing's `sharp` pixels). `Everywhere`: every light's at every landing.
  /// `Punctual`: the point, spot and directional lights' and the sun's at every landing (one
  /// ray each, sharp), the area lights' and emitters' (whose one sample at a landing is noise
  /// the texels' many samples do not have) only across shadow edges.
  enum class LandingDirect { Edges, Everywhere, Punctual };
  LandingDirect landing_direct = LandingDirect::Edges;
  /// World-space filter radius, in texels, of the light step 3's rays read (the kept-ray
  /// solve's), apart from the output's; negative: `filter_radius_texels`. A noisy bright
  /// texel in what the rays read lights every neighbour whose rays land on it: blotches a
  /// few texels wide that no filter of the output's per-texel noise removes.
  float source_filter_radius_texels = -1.0f;
  /// Step 3's landings nearer than `near_regather_texels` texels take the sky and the
  /// indirect light at the landing point itself, from this many cosine rays of their own
  /// (a second gather one level down), instead of reading them from the texels, whose
  /// samples can lie a texel away in other light (corners, ledges). 0: never.
  int near_regather_rays = 0;
  float near_regather_texels = 1.0f;
  /// The regather's rays are read where they land as the fresh rays' are (the punctual lights
  /// at the point, the shadow-edge rule); those that land nearer than `near_regather_texels`
  /// again regather at their point, down to this many levels (1: they read the texels). In a
  /// concave corner the light arrives by several near bounces, each of which a texel read
  /// takes from a sample up to a texel away (docs/light_atlas.md, "Regathers in corners").
  int near_regather_depth = 1;
  /// Rays of each regather below the first level (0: near_regather_rays).
  int near_regather_deep_rays = 0;
  /// Step 3's adaptive sampling: this share of the texels, those whose kept rays read the most
  /// variable light (the spread of the solve's light where they land, independent of the fresh
  /// rays, so that the choice does not bias them), gather `adaptive_passes` more times with
  /// fresh rays of their own and take the mean (0: none; in [0, 1]).
  float adaptive_share = 0.0f;
  int adaptive_passes = 1;  ///< The chosen texels' extra gathers (1..16).
  std::uint64_t seed = 1;
  ProgressCallback progress;  ///< Fraction done in [0, 1]; return false to cancel.
  /// A distributed bake's shard (docs/distributed-bake.md): steps 1-2 run for every texel
  /// (every shard repeats them, bit for bit), step 3 only for the shard's texel blocks
  /// (the others stay 0), and with `part_only` step 4 not at all (filter_gathered runs it
  /// on the merged result).
  WorkShard shard;
  bool part_only = false;
};

struct TexelGatherResult {
  std::vector<glm::vec3> indirect;  ///< Per texel, W/m^2 (0 on empty texels, not dilated).
  /// Per texel, W/m^2: step 1's direct light of the static lights and of the emissive
  /// triangles that stand for an area light (the light the renderer draws live).
  std::vector<glm::vec3> direct;
  /// Per texel, W/m^2: the direct light the renderer does not draw: the sky's (from the
  /// escaping rays of steps 2-3, weighted as `indirect`) and that of emissive triangles no
  /// light stands for (step 1). Filtered in step 4 as `indirect` is.
  std::vector<glm::vec3> baked_direct;
  std::uint64_t rays = 0;
  std::uint64_t shared_rays = 0;     ///< Of `rays`: steps 1-2 (every texel, in every shard).
  std::uint64_t own_rays = 0;        ///< Of `rays`: step 3 for the shard's texels.
  std::vector<std::uint8_t> hidden;  ///< Per texel: seen from behind geometry; the filter skips it.
  /// Per texel, (W/m^2)^2: the variance of the luminance of `indirect` + the sky's part of
  /// `baked_direct` as steps 2-3 estimate them, from the spread of step 3's rays (0 without
  /// fresh rays and on texels another shard gathers); after the denoiser, of its output.
  std::vector<float> variance;
  int iterations = 0;  ///< Bounces the solve ran.
  double direct_seconds = 0.0, solve_seconds = 0.0, gather_seconds = 0.0, filter_seconds = 0.0;
};

/// Errors: invalid settings, cancelled, a layout that is not the one `scene.texels` were
/// rasterized from.
engine::Result<TexelGatherResult> gather_atlas(const StaticBakeScene& scene, const AtlasLayout& layout,
                                               const TexelGatherSettings& settings, ThreadPool& pool);

/// Step 4 on a result whose steps 1-3 ran (merged from shards): the denoiser and the
/// world-space filter of `result.indirect` and `result.baked_direct` as the settings ask:
/// the same step 4, on the same values, as a whole bake's gather_atlas ends with.
engine::Status filter_gathered(const StaticBakeScene& scene, const AtlasLayout& layout,
                               const TexelGatherSettings& settings, ThreadPool& pool, TexelGatherResult& result);

/// The sky's direct irradiance (W/m^2) at every valid texel, shadowed by the static world,
/// from `rays` stratified cosine rays per texel (those that escape bring the sky of their
/// direction), unfiltered: for a bake that does not gather (the VPL final shooting). Errors:
/// rays < 1, a layout that is not the one `scene.texels` were rasterized from.
engine::Result<std::vector<glm::vec3>> sky_direct_light(const StaticBakeScene& scene, const AtlasLayout& layout,
                                                        int rays, std::uint64_t seed, ThreadPool& pool);

/// Irradiance at surface points read from a texel field: each point takes the nearest
/// valid texel within two texels whose normal faces its own (within 60 degrees); 0 where
/// none does. For the VPLs a gathered atlas still feeds (BRF's world probes).
std::vector<glm::vec3> irradiance_at_points(const AtlasTexels& texels, const std::vector<glm::vec3>& irradiance,
                                            float texels_per_metre, std::span<const glm::vec3> points,
                                            std::span<const glm::vec3> normals);

}  // namespace gi
