#pragma once
// Precomputed radiance maps (Szécsi, Szirmay-Kalos, Sbert 2006, "Light animation with
// precomputed light paths on the GPU"): indirect irradiance of the static world under lights
// that move. Bake: entry points over the static surfaces, random walks from each (splitting
// factor, Russian roulette), every path node a virtual light connected by shadow rays to the
// reference points (the light-atlas texels); items S_k summed per (entry point, texel)
// (eq. 2-3) and, entry points being clustered, per (cluster, texel): the cluster's pane.
// Runtime: per light, the weight of every entry point (eq. 4), a cluster's weight the mean
// of its members', the K heaviest clusters' panes summed into an irradiance atlas.
//   gi::Prm prm = gi::bake_prm(scene, {.entry_points = 1024, .clusters = 64}).value();
//   std::vector<float> w = gi::cluster_weights(prm, light, visibility);
//   std::vector<glm::vec3> atlas = gi::sum_panes(prm, gi::select_clusters(w, 32));

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/progress.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>
#include <glm/glm.hpp>

#include "core/work_shard.h"
#include "prm/pane_upsample.h"
#include "prm/prm_panes.h"
#include "uv/atlas_layout.h"

namespace gi {

struct PrmSettings {
  float texels_per_metre = 8.0f;  ///< The light atlas's density: the layout the PRM's sum is read at.
  /// The panes' own density (texels per metre), at most texels_per_metre; 0: the atlas's
  /// (dense panes). Coarser panes are baked on their own layout of the same charts and read
  /// at the atlas's texels by a PaneUpsampler after the sum (docs/prm.md "Panes coarser than
  /// the atlas").
  float pane_texels_per_metre = 0.0f;
  int entry_points = 1024;  ///< N_e, stratified over the static surfaces by area.
  int clusters = 64;        ///< Panes stored: entry points are clustered into this many.
  /// N_s: paths per entry point are N_s x albedo (eq. in §4.1), so every path carries the
  /// same power.
  float splitting = 4.0f;
  int max_path_nodes = 64;  ///< Safety stop of a random walk (Russian roulette ends it first).
  bool kmeans = false;      ///< Refine the median-split kd-tree clusters with k-means (Lloyd) steps.
  /// Panes are stored per atlas tile of this many texels per side, only the tiles where the
  /// cluster's light exceeds `pane_threshold` x its pane's largest value (prm_panes.h).
  int pane_tile_texels = 8;
  float pane_threshold = 0.0f;  ///< 0: every tile holding light (the dense panes exactly).
  std::uint64_t seed = 1;
  unsigned threads = 0;
  ProgressCallback progress;
};

/// One entry point y_1: where moving lights first hit the static world.
struct PrmEntryPoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float area_m2 = 0.0f;       ///< The surface it stands for (regularizes eq. 4 near a light).
  std::uint32_t cluster = 0;  ///< Its cluster (pane).
};

struct PrmStats {
  std::size_t paths = 0;
  std::size_t path_nodes = 0;  ///< Virtual lights.
  std::uint64_t rays = 0;
  double walk_seconds = 0.0;
  double pane_seconds = 0.0;
  double total_seconds = 0.0;
};

/// The light atlas a PRM with coarse panes is read at: its layout and the chart-respecting
/// bilinear read of the pane layout at its texels (pane_upsample.h).
struct PrmAtlasRead {
  AtlasLayout layout;
  std::shared_ptr<const PaneUpsampler> upsampler;  ///< Shared: immutable, built once per bake or load.
};

/// A baked PRM. Panes cover `texels`: every texel a triangle covers plus the gutter rings
/// the pane layout dilates into (dilation is linear, so it is applied to each pane at bake
/// time and the runtime sum needs none). The pane layout is the light atlas's unless the
/// panes are coarser (`atlas` set): then sums are upsampled to the atlas.
struct Prm {
  AtlasLayout layout;  ///< The panes' layout (the light atlas's when `atlas` is empty).
  int width = 0;       ///< Of the pane layout.
  int height = 0;
  std::vector<std::uint32_t> texels;  ///< Pane texel index (y * width + x) of each pane element, ascending.
  std::vector<PrmEntryPoint> entries;
  int cluster_count = 0;
  std::vector<std::uint32_t> cluster_size;  ///< Members per cluster.
  /// Pane c at element i: the indirect irradiance (W/m^2) at texel texels[i] when every entry
  /// point of cluster c receives unit irradiance (the sum of the members' items S_k), stored
  /// only on the tiles the cluster lights (prm_panes.h; dense_panes(prm) gives them all).
  PrmPanes panes;
  PrmSettings settings;
  PrmStats stats;
  /// Set when the panes are coarser than the light atlas (settings.pane_texels_per_metre).
  std::optional<PrmAtlasRead> atlas;

  std::size_t pane_size() const { return texels.size(); }
  /// The light atlas the runtime writes (the renderer's TEXCOORD_1): `layout` for dense panes.
  const AtlasLayout& atlas_layout() const { return atlas ? atlas->layout : layout; }
  int atlas_width() const { return atlas ? atlas->layout.width : width; }
  int atlas_height() const { return atlas ? atlas->layout.height : height; }
};

/// The density the panes are baked at: settings.pane_texels_per_metre, or the atlas's when 0.
inline float pane_density(const PrmSettings& s) {
  return s.pane_texels_per_metre > 0.0f ? s.pane_texels_per_metre : s.texels_per_metre;
}
/// True when the panes are baked coarser than the atlas (a PaneUpsampler reads them).
inline bool coarse_panes(const PrmSettings& s) { return pane_density(s) < s.texels_per_metre; }
/// Sets the atlas density, keeping the panes' ratio to it (a preset's coarse panes stay as coarse).
inline void set_prm_atlas_density(PrmSettings& s, float texels_per_metre) {
  if (s.pane_texels_per_metre > 0.0f && s.texels_per_metre > 0.0f)
    s.pane_texels_per_metre *= texels_per_metre / s.texels_per_metre;
  s.texels_per_metre = texels_per_metre;
}

/// The upsampler from `prm`'s pane layout to `atlas` (the light atlas of the same static
/// world), rasterizing `atlas` over `input`'s static meshes. Error: layouts of other charts.
engine::Result<PrmAtlasRead> prm_atlas_read(const Prm& prm, AtlasLayout atlas, const BakeInput& input);

/// prm's panes dense: pane c, element i, channel ch at [(c * texels.size() + i) * 3 + ch].
inline std::vector<float> dense_panes(const Prm& prm) {
  return dense_panes(prm.panes, prm.texels.size(), prm.cluster_count);
}

/// Replaces prm's panes by `dense` (dense_panes' order) cut into prm.settings' blocks.
inline void set_dense_panes(Prm& prm, std::span<const float> dense) {
  prm.panes = sparse_panes(prm.texels, prm.width, prm.cluster_count, dense,
                           {.tile_texels = prm.settings.pane_tile_texels, .threshold = prm.settings.pane_threshold});
}

/// What one shard of a distributed bake computed (docs/distributed-bake.md): the items of
/// its texel blocks (WorkShard over the valid atlas texels in index order), every cluster's
/// sum, before dilation. Entry points, clustering and the random walks are repeated bit for
/// bit by every shard (and the entry points and clusters by the merge) instead of shipped.
struct PrmShardPart {
  std::vector<std::uint32_t> texels;  ///< Atlas texel indices, ascending.
  int cluster_count = 0;
  /// Texel k of `texels`, cluster c, channel ch at values[(k * cluster_count + c) * 3 + ch].
  std::vector<float> values;
  std::size_t paths = 0, path_nodes = 0;  ///< Of the walks (the same in every shard).
  std::uint64_t walk_rays = 0;            ///< Rays of the walks (the same in every shard).
  std::uint64_t pane_rays = 0;            ///< Shadow rays of this shard's texels.
};

/// Shard `shard` of bake_prm(input, settings).
engine::Result<PrmShardPart> bake_prm_shard(const BakeInput& input, const PrmSettings& settings, WorkShard shard);

/// bake_prm(input, settings), bit for bit, from the parts of shards 0..N-1 (parts[i] of
/// shard i). Error when a part's texels or clusters are not its shard's.
engine::Result<Prm> merge_prm(const BakeInput& input, const PrmSettings& settings,
                              const std::vector<PrmShardPart>& parts);

/// preview / medium / high (docs/sweeps/prm_spot_chamber.md). The pane density follows the
/// light atlas preset of the same name, so both share one uv1 layout.
engine::Result<PrmSettings> prm_preset(std::string_view name);

/// Bakes the PRM of the Static instances of `input`. Errors: no static geometry, settings out
/// of range, cancelled.
engine::Result<Prm> bake_prm(const BakeInput& input, const PrmSettings& settings);

/// bake_prm gathering only at the atlas texels flagged in `only` (one flag per texel of the
/// atlas; the other texels stay 0 before dilation): what a sweep scoring a subset of texels
/// needs on a level too large to bake dense panes whole. A texel's sum is its own (as in a
/// sharded bake), so the flagged texels hold exactly what a whole bake gives them. Dense
/// panes without a threshold only (a threshold compares blocks with the whole pane's peak).
/// Errors: coarse panes or a threshold, flags of another size, those of bake_prm.
engine::Result<Prm> bake_prm_at(const BakeInput& input, const PrmSettings& settings,
                                const std::vector<std::uint8_t>& only);

}  // namespace gi
