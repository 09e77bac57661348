#pragma once
// The light-atlas baker (Schärfig, Stamminger, Hormann 2016, "Creating light atlases with
// multi-bounce indirect illumination"): multi-bounce diffuse indirect irradiance of the
// static world under static lights, stored per texel of the scene's light atlas (uv1).
//   auto bake = gi::bake_light_atlas(input, gi::light_atlas_preset("medium").value());  // input: gi/bake_input.h
//   // bake->irradiance[y * bake->width + x]: indirect irradiance (W/m^2); shade albedo/pi x E.
//
// Steps (paper section in brackets):
//   1. VPLs spread uniformly over the static surfaces, each owning ~10 sample points; a
//      VPL's patch area is the area its sample points stand for (§3.1, eq. 1).
//   2. Direct light to every VPL, averaged over its sample points with shadow rays (§3.2,
//      eq. 5-6).
//   3. Progressive refinement: the VPL with the largest unshot power shoots into all VPLs
//      with the symmetric scaled form factor (§3.3, eq. 7-8), one generation per bounce.
//   4. Final shooting: every VPL's reflected power into the atlas texels it sees (§4.1,
//      eq. 9), visibility by one shadow ray per (texel, VPL).
//   5. Incremental update when static lights change (§6.2): VPL powers redistributed, only
//      the VPLs whose power changed by more than a threshold re-shot as differences.
// Bit-identical for any thread count: every random number comes from (seed, item id).

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/progress.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>
#include <glm/glm.hpp>

#include "light_atlas/texel_gather.h"
#include "transport/vpl_set.h"
#include "uv/atlas_layout.h"

namespace gi {

struct LightAtlasSettings {
  float texels_per_metre = 16.0f;  ///< Atlas density requested from the layout (uv/atlas_layout.h).
  int vpl_count = 1000;            ///< Target number of VPLs over all static surfaces.
  int samples_per_vpl = 10;        ///< Sample points per VPL (visibility fraction, patch area).
  /// Indirect bounces carried by the atlas: 1 = light reflected once (VPLs hold direct light
  /// only), b = b-1 generations of VPL-to-VPL shooting before the final shooting.
  int bounces = 5;
  /// A generation stops early when the largest unshot power falls below this fraction of
  /// the largest power after direct lighting (paper §3.3's threshold).
  float unshot_threshold = 1e-4f;
  int area_light_samples = 64;  ///< Point samples per area light or emissive triangle (>= 1).
  /// The atlas always holds the indirect light and the direct light the renderer does not
  /// draw (the sky's, shadowed by the level, and emitters no light stands for); true adds
  /// the static lights' direct light too (the renderer then draws none of theirs on the
  /// static surfaces that read the atlas).
  bool include_direct = false;
  /// How step 4 fills the texels. VplShooting: the paper's final shooting (texels x VPLs
  /// shadow rays). TexelGather: a final gather from every texel (texel_gather.h; `gather`
  /// holds its knobs, its seed and progress are this struct's); the VPL solution of steps
  /// 1-3 is then kept only for what reads it (BRF's world probes).
  enum class FinalPass : std::uint8_t { VplShooting, TexelGather };
  FinalPass final_pass = FinalPass::VplShooting;
  TexelGatherSettings gather;
  std::uint64_t seed = 1;
  unsigned threads = 0;       ///< 0: all hardware threads. The result does not depend on it.
  ProgressCallback progress;  ///< Fraction done in [0, 1]; return false to cancel.
};

/// Where the bake's texel samples lie: VisibleSurface for the gather, Raster for the VPL
/// final shooting (its near field is missing next to concave edges).
TexelPlacement texel_placement(const LightAtlasSettings& settings);

/// preview / medium / high, chosen from the measured Pareto front (docs/sweeps/).
engine::Result<LightAtlasSettings> light_atlas_preset(std::string_view name);
std::vector<std::string> light_atlas_preset_names();

struct LightAtlasStats {
  std::size_t vpls = 0;
  std::size_t sample_points = 0;
  std::size_t light_points = 0;  ///< Point emitters after sampling area lights / emissive triangles.
  std::size_t shots = 0;         ///< VPL-to-VPL shooting steps (§3.3).
  std::size_t valid_texels = 0;
  std::uint64_t rays = 0;          ///< Shadow rays cast in total.
  double layout_seconds = 0.0;     ///< Charting, packing and rasterizing the atlas.
  double prepare_seconds = 0.0;    ///< Ray-tracing scene, texel sample points, emitters.
  double vpl_seconds = 0.0;        ///< Distribution of VPLs and sample points.
  double direct_seconds = 0.0;     ///< Direct light to the VPLs.
  double propagate_seconds = 0.0;  ///< Progressive refinement.
  double final_seconds = 0.0;      ///< Final shooting (or gather) into the atlas.
  int gather_iterations = 0;       ///< TexelGather: bounces the kept-ray solve ran.
  double total_seconds = 0.0;      ///< Everything, layout and rasterization included.
};

/// A baked light atlas.
struct LightAtlasBake {
  AtlasLayout layout;  ///< The uv1 parameterization the atlas belongs to.
  int width = 0;
  int height = 0;
  /// Irradiance per texel (W/m^2, linear RGB), texel (x, y) at y * width + x, dilated into
  /// the chart gutters so bilinear reads inside a chart never see empty texels: the
  /// indirect light plus the direct light the renderer does not draw (the sky, shadowed by
  /// the static world; emissive surfaces no light stands for), plus the static lights'
  /// direct light when settings.include_direct (docs/scene-format.md, "What is baked and
  /// what is drawn live").
  std::vector<glm::vec3> irradiance;
  std::vector<std::uint8_t> valid;  ///< Texels a triangle covers.
  /// Per texel, W/m^2: the static lights' direct light the final gather computed (what
  /// include_direct adds to `irradiance`, not dilated), so `irradiance` + it is the whole
  /// lightmap of a bake without include_direct (the sweeps' truth comparison). Empty for the
  /// VPL final shooting.
  std::vector<glm::vec3> live_direct;
  LightAtlasSettings settings;
  LightAtlasStats stats;
  /// The VPL solution (positions, patches, powers), kept for incremental updates (§6.2).
  VplSet vpls;
  std::vector<glm::vec3> vpl_power;  ///< Reflected power E_i of every VPL (W), what step 4 shot.
};

/// Bakes the Static instances of `input` lit by its lights that do not move and its
/// emissive static surfaces. Errors: no static geometry, invalid settings,
/// cancellation, or a layout that cannot be built.
engine::Result<LightAtlasBake> bake_light_atlas(const BakeInput& input, const LightAtlasSettings& settings);

/// What one shard of a distributed bake computed (docs/distributed-bake.md): the final
/// gather (texel_gather.h step 3) of its texel blocks (WorkShard over the gather's valid
/// texels in index order), unfiltered, with the direct light and the hidden flag of those
/// texels. The layout, the texels, steps 1-2 and the VPLs are repeated bit for bit by every
/// shard and by the merge instead of being shipped (measured in docs/distributed-bake.md).
struct LightAtlasShardPart {
  std::vector<std::uint32_t> texels;    ///< Atlas texel indices, ascending.
  std::vector<glm::vec3> indirect;      ///< Per texel of `texels`: steps 2-3's irradiance.
  std::vector<glm::vec3> direct;        ///< Per texel of `texels`: TexelGatherResult::direct.
  std::vector<glm::vec3> baked_direct;  ///< Per texel of `texels`: TexelGatherResult::baked_direct (unfiltered).
  std::vector<std::uint8_t> hidden;     ///< Per texel of `texels`.
  std::vector<float> variance;          ///< Per texel of `texels`: TexelGatherResult::variance (the denoiser's guide).
  std::uint64_t shared_rays = 0;        ///< Rays of steps 1-2 (the same in every shard).
  std::uint64_t own_rays = 0;           ///< Rays of step 3 for `texels`.
};

/// Shard `shard` of bake_light_atlas(input, settings) (a TexelGather final pass; the VPL
/// shooting pass cannot be sharded: ErrorKind::Invalid).
engine::Result<LightAtlasShardPart> bake_light_atlas_shard(const BakeInput& input, const LightAtlasSettings& settings,
                                                           WorkShard shard);

/// The bake of bake_light_atlas(input, settings), bit for bit, from the parts of shards
/// 0..N-1 (parts[i] of shard i). Error when a part's texels are not its shard's.
engine::Result<LightAtlasBake> merge_light_atlas(const BakeInput& input, const LightAtlasSettings& settings,
                                                 const std::vector<LightAtlasShardPart>& parts);

struct LightAtlasUpdateStats {
  std::size_t reshot_vpls = 0;  ///< VPLs whose power change passed the threshold.
  double seconds = 0.0;
};

/// Paper §6.2: `previous` was baked from `input` with other light settings (same geometry).
/// Recomputes the VPL solution under the input's current lights, then re-shoots into the
/// atlas only the differences E_new - E_old of VPLs whose change exceeds
/// `relative_threshold` x the largest new VPL power. Threshold 0 reproduces a full re-bake
/// up to float rounding. The direct light the atlas holds of the sky and of unlit emitters
/// is left as baked: an update is for the static lights' settings, not the sky's.
engine::Result<LightAtlasUpdateStats> update_light_atlas(const BakeInput& input, LightAtlasBake& previous,
                                                         float relative_threshold);

}  // namespace gi
