#include "prm/prm.h"

#include "core/color.h"
#include "core/stopwatch.h"
#include "raytrace/material_lookup.h"
#include "raytrace/path_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "core/random.h"
#include "core/thread_pool.h"
#include "prm/entry_clusters.h"
#include "raytrace/ray_offset.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"
#include "transport/vpl_set.h"
#include "uv/atlas_density.h"
#include "uv/atlas_dilation.h"
#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace gi {
namespace {

using Clock = std::chrono::steady_clock;

engine::Status validate(const PrmSettings& s) {
  const auto bad = [](std::string what) { return engine::invalid_request("PRM settings: " + what); };
  if (!(s.texels_per_metre > 0.0f) || s.texels_per_metre > kMaxTexelsPerMetre)
    return bad("texels_per_metre " + std::to_string(s.texels_per_metre) + " is outside (0, 10^4]");
  if (!(s.pane_texels_per_metre >= 0.0f) || s.pane_texels_per_metre > s.texels_per_metre)
    return bad("pane_texels_per_metre " + std::to_string(s.pane_texels_per_metre) +
               " is outside [0, texels_per_metre] (0: the atlas's density)");
  if (s.entry_points < 1 || s.entry_points > 1'000'000)
    return bad("entry_points " + std::to_string(s.entry_points) + " is outside 1..10^6");
  if (s.clusters < 1 || s.clusters > 65536)
    return bad("clusters " + std::to_string(s.clusters) + " is outside 1..65536");
  if (!(s.splitting > 0.0f) || s.splitting > 1024.0f) return bad("splitting must be in (0, 1024]");
  if (s.max_path_nodes < 1 || s.max_path_nodes > 4096) return bad("max_path_nodes must be in 1..4096");
  if (s.pane_tile_texels < 1 || s.pane_tile_texels > 256) return bad("pane_tile_texels must be in 1..256");
  if (!(s.pane_threshold >= 0.0f) || s.pane_threshold > 1.0f) return bad("pane_threshold must be in [0, 1]");
  return {};
}

// A path node acting as a virtual light: a diffuse emitter of `power` (W per unit
// irradiance at its entry point) at `position` facing `normal`.
struct PathNode {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec3 power;
};

// The random walks of one entry point (§4.1): N_s x a(y_1) paths, each carrying
// albedo x area / (N_s a) so that every path has the same weight; cosine sampling from the
// entry point, then at every hit Russian roulette with the hit's albedo and cosine
// (diffuse) sampling. Every node is a virtual light: y_1 shines the first reflection, y_j
// the j-th (eq. 2: the product of BRDFs over the path density leaves the albedos' ratio).
std::vector<PathNode> random_walks(const VplSet& entries, std::size_t k, const StaticBakeScene& s,
                                   const std::vector<glm::vec3>& triangle_albedo, const PrmSettings& settings,
                                   std::uint64_t& rays, std::size_t& paths) {
  std::vector<PathNode> nodes;
  Pcg32 rng = Pcg32::for_item(settings.seed, k);
  const glm::vec3 rho = entries.albedo[k];
  const float a = max_component(rho);
  if (!(a > 0.0f)) return nodes;
  const float expected = settings.splitting * a;
  auto count = static_cast<int>(expected);
  if (rng.next_float() < expected - static_cast<float>(count)) ++count;
  const glm::vec3 path_power = rho * entries.area_m2[k] / expected;
  for (int p = 0; p < count; ++p) {
    ++paths;
    glm::vec3 position = entries.position[k];
    glm::vec3 normal = entries.normal[k];
    glm::vec3 power = path_power;
    nodes.push_back({position, normal, power});
    for (int depth = 1; depth < settings.max_path_nodes; ++depth) {
      const float u1 = rng.next_float(), u2 = rng.next_float(), u_rr = rng.next_float();
      const glm::vec3 dir = sample_cosine_hemisphere(normal, u1, u2);
      ++rays;
      const Hit hit = s.caster->intersect(Ray{offset_ray_origin(position, normal), 0.0f, dir});
      if (!hit.valid()) break;
      const glm::vec3 ng = glm::normalize(hit.geometric_normal);
      if (glm::dot(ng, dir) >= 0.0f) break;  // the back of a one-sided surface absorbs
      const std::uint32_t tri = s.triangle_of(hit);
      // Textured: the material lookup at the hit, for the ray cone of a bounce ray (the
      // path tracer's bounce spread, path_tracer.h).
      const ShadingTriangle& st = s.index.triangles[tri];
      const glm::vec3 albedo =
          s.scene.materials[st.material].textured()
              ? albedo_at(s.scene, st, hit.barycentric, hit.t * PathTracerSettings{}.bounce_spread_rad)
              : triangle_albedo[tri];
      const float q = std::min(1.0f, max_component(albedo));
      if (!(u_rr < q)) break;
      position = s.index.triangles[tri].p0 + hit.barycentric.x * s.index.triangles[tri].e1 +
                 hit.barycentric.y * s.index.triangles[tri].e2;
      normal = ng;
      power *= albedo / q;
      nodes.push_back({position, normal, power});
    }
  }
  return nodes;
}

// How bake_prm runs: whole, as one shard (fills *part, stops before dilation), or as the
// merge of the shards' parts (no walks, no shadow rays).
struct PrmRun {
  WorkShard shard;
  PrmShardPart* part = nullptr;
  const std::vector<PrmShardPart>* parts = nullptr;
  const std::vector<std::uint8_t>* only = nullptr;  ///< bake_prm_at's texel flags.
};

// The folded albedo of every triangle of the snapshot (a textured one's: the texture's mean
// over the triangle).
std::vector<glm::vec3> triangle_albedos(const StaticBakeScene& s) {
  std::unordered_map<std::uint32_t, glm::vec3> material_albedo;
  std::vector<glm::vec3> triangle_albedo(s.index.triangles.size());
  for (std::size_t t = 0; t < triangle_albedo.size(); ++t) {
    const std::uint32_t m = s.index.triangles[t].material;
    if (s.scene.materials[m].textured()) {  // the texture's mean over the triangle
      triangle_albedo[t] = gi::triangle_albedo(s.scene, s.index.triangles[t]);
      continue;
    }
    auto it = material_albedo.find(m);
    if (it == material_albedo.end())
      it = material_albedo.emplace(m, engine::gltf_hemispherical_albedo(s.scene.materials[m].brdf).sum()).first;
    triangle_albedo[t] = it->second;
  }
  return triangle_albedo;
}

// Clusters the entry points into prm.entries, cluster_count and cluster_size: the normal
// counts like a tenth of the scene's size.
void cluster_entries(const VplSet& entries, const StaticBakeScene& s, const PrmSettings& settings, Prm& prm) {
  const auto cluster_of =
      cluster_entry_points(entries.position, entries.normal, settings.clusters,
                           0.1f * std::max(s.index.scene_radius_m, 1e-6f), settings.kmeans ? 10 : 0);
  prm.cluster_count = 0;
  for (std::uint32_t c : cluster_of) prm.cluster_count = std::max(prm.cluster_count, static_cast<int>(c) + 1);
  prm.cluster_size.assign(static_cast<std::size_t>(prm.cluster_count), 0);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    prm.entries.push_back({entries.position[k], entries.normal[k], entries.area_m2[k], cluster_of[k]});
    ++prm.cluster_size[cluster_of[k]];
  }
}

// The merge: the shards' items in place of the walks and shadow rays, written into `full`
// ([cluster][texel]) after checking each part is its shard's of this atlas.
engine::Status merge_shard_parts(const std::vector<PrmShardPart>& parts, const std::vector<std::uint32_t>& valid,
                                 std::size_t n_texels, Prm& prm, std::vector<glm::vec3>& full) {
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  const auto count = static_cast<std::uint32_t>(parts.size());
  for (std::uint32_t i = 0; i < count; ++i) {
    const PrmShardPart& p = parts[i];
    const WorkShard shard{.index = i, .count = count};
    std::vector<std::uint32_t> expected;
    for (std::size_t w = 0; w < valid.size(); ++w)
      if (shard.owns(w)) expected.push_back(valid[w]);
    if (p.texels != expected || p.cluster_count != prm.cluster_count ||
        p.values.size() != expected.size() * clusters * 3)
      return engine::Error{.message = "PRM shard " + std::to_string(i) + " of " + std::to_string(count) +
                                      ": its texels or clusters are not that shard's of this scene's atlas"};
    for (std::size_t k = 0; k < expected.size(); ++k)
      for (std::size_t c = 0; c < clusters; ++c)
        full[c * n_texels + expected[k]] =
            glm::vec3(p.values[(k * clusters + c) * 3], p.values[(k * clusters + c) * 3 + 1],
                      p.values[(k * clusters + c) * 3 + 2]);
    prm.stats.rays += p.pane_rays;
  }
  if (count > 0) {
    const PrmShardPart& first = parts.front();
    prm.stats.rays += first.walk_rays;
    prm.stats.paths = first.paths;
    prm.stats.path_nodes = first.path_nodes;
  }
  return {};
}

// Random walks, per entry point in parallel (each from its own stream), counted into prm.stats.
std::vector<std::vector<PathNode>> walk_entries(const VplSet& entries, const StaticBakeScene& s,
                                                const std::vector<glm::vec3>& triangle_albedo,
                                                const PrmSettings& settings, ThreadPool& pool, Prm& prm) {
  const std::size_t n_entries = entries.size();
  std::vector<std::vector<PathNode>> walks(n_entries);
  std::vector<std::uint64_t> walk_rays(n_entries, 0);
  std::vector<std::size_t> walk_paths(n_entries, 0);
  pool.parallel_for(n_entries, [&](std::size_t k) {
    walks[k] = random_walks(entries, k, s, triangle_albedo, settings, walk_rays[k], walk_paths[k]);
  });
  for (std::size_t k = 0; k < n_entries; ++k) {
    prm.stats.rays += walk_rays[k];
    prm.stats.paths += walk_paths[k];
    prm.stats.path_nodes += walks[k].size();
  }
  return walks;
}

// Items (eq. 3): every virtual light connected to every reference point it sees, summed
// per (cluster, texel) into `full`, for the valid texels `mine` indexes. Parallel over texels;
// each texel visits the nodes in a fixed order, so the sums do not depend on the thread count.
// The near field is regularized by the entry point's area (cos cos / (pi d^2 + A),
// point_emitters.h). Returns the shadow rays traced.
engine::Result<std::uint64_t> gather_items(const StaticBakeScene& s, const PrmSettings& settings, const Prm& prm,
                                           const std::vector<std::vector<PathNode>>& walks,
                                           const std::vector<std::uint32_t>& valid,
                                           const std::vector<std::size_t>& mine, ThreadPool& pool,
                                           std::vector<glm::vec3>& full) {
  const AtlasTexels& tex = s.texels;
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  const std::size_t n_entries = walks.size();
  std::atomic<std::uint64_t> rays{0};
  const std::size_t batches = std::clamp<std::size_t>(mine.size() / 64, 1, 100);
  for (std::size_t b = 0; b < batches; ++b) {
    const std::size_t begin = mine.size() * b / batches, end = mine.size() * (b + 1) / batches;
    pool.parallel_for(
        end - begin,
        [&](std::size_t w) {
          const std::uint32_t t = valid[mine[begin + w]];
          const glm::vec3 p = tex.position[t], n = tex.normal[t];
          std::vector<glm::dvec3> sum(clusters, glm::dvec3(0.0));
          std::uint64_t local = 0;
          for (std::size_t k = 0; k < n_entries; ++k) {
            const float area = prm.entries[k].area_m2 / settings.splitting;
            glm::dvec3 item(0.0);
            for (const PathNode& v : walks[k]) {
              const float f = lambertian_kernel(v.position, v.normal, area, false, p, n, 0.0f);
              if (f <= 0.0f) continue;
              ++local;
              if (segment_visible(*s.caster, p, n, v.position, v.normal))
                item += glm::dvec3(v.power) * static_cast<double>(f);
            }
            sum[prm.entries[k].cluster] += item;
          }
          for (std::size_t c = 0; c < clusters; ++c) full[c * tex.valid.size() + t] = glm::vec3(sum[c]);
          rays += local;
        },
        4);
    if (settings.progress && !settings.progress(0.05 + 0.9 * static_cast<double>(b + 1) / static_cast<double>(batches)))
      return engine::cancelled_error("PRM bake");
  }
  return rays.load();
}

// A shard's part: its texels' items, with the walk counts every shard shares.
void fill_shard_part(const Prm& prm, std::uint64_t pane_rays, const std::vector<std::uint32_t>& valid,
                     const std::vector<std::size_t>& mine, const std::vector<glm::vec3>& full, std::size_t n_texels,
                     PrmShardPart& p) {
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  p.cluster_count = prm.cluster_count;
  p.paths = prm.stats.paths;
  p.path_nodes = prm.stats.path_nodes;
  p.walk_rays = prm.stats.rays;
  p.pane_rays = pane_rays;
  p.texels.reserve(mine.size());
  p.values.reserve(mine.size() * clusters * 3);
  for (std::size_t w : mine) {
    const std::uint32_t t = valid[w];
    p.texels.push_back(t);
    for (std::size_t c = 0; c < clusters; ++c)
      for (int ch = 0; ch < 3; ++ch) p.values.push_back(full[c * n_texels + t][ch]);
  }
}

// Coarse panes: the texels the PaneUpsampler can read, those inside a chart's footprint (it
// takes taps only there, pane_upsample.h). The dilation rings in the gutters between the
// footprints are read by nobody: the upsampler fills the atlas's own rings.
void keep_chart_footprints(const AtlasLayout& layout, std::vector<std::uint8_t>& filled) {
  std::vector<std::uint8_t> in_chart(filled.size(), 0);
  for (const AtlasChart& chart : layout.charts)
    for (int y = chart.origin.y; y < chart.origin.y + chart.size.y; ++y)
      for (int x = chart.origin.x; x < chart.origin.x + chart.size.x; ++x)
        in_chart[static_cast<std::size_t>(y) * static_cast<std::size_t>(layout.width) + static_cast<std::size_t>(x)] =
            1;
  for (std::size_t t = 0; t < filled.size(); ++t) filled[t] = filled[t] && in_chart[t];
}

// Dilation is linear: dilate every pane like the light atlas, keep the filled texels (of
// coarse panes, only those inside the charts' footprints: keep_chart_footprints).
void dilate_panes(const AtlasTexels& tex, std::vector<glm::vec3>& full, Prm& prm) {
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  const int rings = atlas_gutter_rings(prm.layout.padding_texels);
  std::vector<std::uint8_t> filled;
  for (std::size_t c = 0; c < clusters; ++c)
    filled = dilate<glm::vec3>(std::span<glm::vec3>(full.data() + c * tex.valid.size(), tex.valid.size()), prm.width,
                               prm.height, tex.valid, rings);
  if (clusters == 0) filled = tex.valid;
  if (coarse_panes(prm.settings)) keep_chart_footprints(prm.layout, filled);
  for (std::size_t t = 0; t < filled.size(); ++t)
    if (filled[t]) prm.texels.push_back(static_cast<std::uint32_t>(t));
  std::vector<float> dense(clusters * prm.texels.size() * 3);
  for (std::size_t c = 0; c < clusters; ++c)
    for (std::size_t i = 0; i < prm.texels.size(); ++i)
      for (int ch = 0; ch < 3; ++ch)
        dense[(c * prm.texels.size() + i) * 3 + static_cast<std::size_t>(ch)] =
            full[c * tex.valid.size() + prm.texels[i]][ch];
  full = {};
  set_dense_panes(prm, dense);
}

// Panes coarser than the atlas: the light atlas's layout and the upsampler that reads the
// panes at its texels (pane_upsample.h); nothing for panes at the atlas's density.
engine::Status attach_atlas_read(const BakeInput& input, const PrmSettings& settings, Prm& prm) {
  if (!coarse_panes(settings)) return {};
  auto atlas = static_world_layout(input, settings.texels_per_metre);
  if (!atlas) return atlas.error();
  auto read = prm_atlas_read(prm, std::move(atlas).value(), input);
  if (!read) return read.error();
  prm.atlas = std::move(read).value();
  return {};
}

engine::Result<Prm> bake_prm_run(const BakeInput& input, const PrmSettings& settings, const PrmRun& run) {
  if (auto ok = validate(settings); !ok) return ok.error();
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  const auto t_start = Clock::now();
  auto layout = static_world_layout(input, pane_density(settings));
  if (!layout) return layout.error();
  auto prepared = prepare_static_scene(input, *layout, BakeLights::None);
  if (!prepared) return prepared.error();
  const StaticBakeScene& s = *prepared;
  ThreadPool pool(settings.threads);

  Prm prm;
  prm.settings = settings;
  prm.layout = std::move(layout).value();
  prm.width = prm.layout.width;
  prm.height = prm.layout.height;

  // Entry points: stratified by area over the static surfaces (one sample per patch of the
  // VPL distribution, so every chart keeps its exact area).
  auto entries = distribute_vpls(s.scene, s.index,
                                 {.vpl_count = settings.entry_points, .samples_per_vpl = 1, .seed = settings.seed});
  if (!entries) return entries.error();
  const std::vector<glm::vec3> triangle_albedo = triangle_albedos(s);
  cluster_entries(*entries, s, settings, prm);

  const AtlasTexels& tex = s.texels;
  std::vector<std::uint32_t> valid;
  for (std::size_t t = 0; t < tex.valid.size(); ++t)
    if (tex.valid[t]) valid.push_back(static_cast<std::uint32_t>(t));
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  std::vector<glm::vec3> full(clusters * tex.valid.size(), glm::vec3(0.0f));  // [cluster][texel]
  auto t0 = Clock::now();
  if (run.parts) {
    if (engine::Status st = merge_shard_parts(*run.parts, valid, tex.valid.size(), prm, full); !st) return st.error();
    if (settings.progress && !settings.progress(0.95)) return engine::cancelled_error("PRM merge");
  } else {
    const std::vector<std::vector<PathNode>> walks = walk_entries(*entries, s, triangle_albedo, settings, pool, prm);
    prm.stats.walk_seconds = seconds_since(t0);
    if (settings.progress && !settings.progress(0.05)) return engine::cancelled_error("PRM bake");
    t0 = Clock::now();
    std::vector<std::size_t> mine = run.shard.items(valid.size());  // all of them in a whole bake
    if (run.only) std::erase_if(mine, [&](std::size_t i) { return (*run.only)[valid[i]] == 0; });
    auto rays = gather_items(s, settings, prm, walks, valid, mine, pool, full);
    if (!rays) return rays.error();
    if (run.part) {
      fill_shard_part(prm, *rays, valid, mine, full, tex.valid.size(), *run.part);
      return Prm{};
    }
    prm.stats.rays += *rays;
  }

  dilate_panes(tex, full, prm);
  if (engine::Status st = attach_atlas_read(input, settings, prm); !st) return st.error();
  prm.stats.pane_seconds = seconds_since(t0);
  prm.stats.total_seconds = seconds_since(t_start);
  return prm;
}

}  // namespace

engine::Result<Prm> bake_prm(const BakeInput& input, const PrmSettings& settings) {
  return bake_prm_run(input, settings, {});
}

engine::Result<Prm> bake_prm_at(const BakeInput& input, const PrmSettings& settings,
                                const std::vector<std::uint8_t>& only) {
  if (coarse_panes(settings) || settings.pane_threshold != 0.0f)
    return engine::invalid_request("PRM at a texel subset: only dense panes without a threshold");
  auto layout = static_world_layout(input, pane_density(settings));
  if (!layout) return layout.error();
  if (only.size() != static_cast<std::size_t>(layout->width) * static_cast<std::size_t>(layout->height))
    return engine::invalid_request("PRM at a texel subset: one flag per texel of the atlas");
  return bake_prm_run(input, settings, {.shard = {}, .part = nullptr, .parts = nullptr, .only = &only});
}

engine::Result<PrmShardPart> bake_prm_shard(const BakeInput& input, const PrmSettings& settings, WorkShard shard) {
  if (shard.count == 0 || shard.index >= shard.count)
    return engine::invalid_request("PRM shard " + std::to_string(shard.index) + " of " + std::to_string(shard.count) +
                                   " does not exist");
  PrmShardPart part;
  auto done = bake_prm_run(input, settings, {.shard = shard, .part = &part, .parts = nullptr});
  if (!done) return done.error();
  return part;
}

engine::Result<Prm> merge_prm(const BakeInput& input, const PrmSettings& settings,
                              const std::vector<PrmShardPart>& parts) {
  if (parts.empty()) return engine::invalid_request("PRM merge: no shard");
  return bake_prm_run(input, settings, {.shard = {}, .part = nullptr, .parts = &parts});
}

engine::Result<PrmAtlasRead> prm_atlas_read(const Prm& prm, AtlasLayout atlas, const BakeInput& input) {
  const AtlasTexels fine = rasterize_atlas(atlas, atlas_inputs_from(input));
  // The atlas's gutter rings, as the light atlas dilates its own.
  auto up = PaneUpsampler::build(prm.layout, prm.texels, atlas, fine, atlas_gutter_rings(atlas.padding_texels));
  if (!up) return up.error();
  return PrmAtlasRead{.layout = std::move(atlas),
                      .upsampler = std::make_shared<const PaneUpsampler>(std::move(up).value())};
}

engine::Result<PrmSettings> prm_preset(std::string_view name) {
  auto density = atlas_density_preset(name);
  if (!density)
    return engine::invalid_request("unknown PRM preset '" + std::string(name) + "' (preview, medium, high)");
  PrmSettings s;
  s.texels_per_metre = *density;
  // Blocks below 1% of their cluster's peak dropped: the demo level keeps 53% of its pane
  // texels at the same error against the path tracer (docs/prm.md "Sparse panes").
  s.pane_threshold = 0.01f;
  // Medium: panes at half the atlas's density, 1.06-1.07x the dense panes' error on the demo
  // level for a third of their memory and a quarter of the bake (docs/prm.md "Panes coarser
  // than the atlas"). Preview keeps dense panes: its 16 clusters save less pane memory than
  // the upsampling taps cost, and its relight got slower (prm_relight_bench, docs/prm.md).
  // High keeps dense panes: not measured there yet.
  if (name == "preview") {
    s.entry_points = 512, s.clusters = 16, s.splitting = 2.0f;
  } else if (name == "medium") {
    s.entry_points = 1024, s.clusters = 64, s.splitting = 4.0f;
    s.pane_texels_per_metre = 0.5f * s.texels_per_metre;
  } else {
    s.entry_points = 4096, s.clusters = 128, s.splitting = 4.0f;
  }
  return s;
}

}  // namespace gi
