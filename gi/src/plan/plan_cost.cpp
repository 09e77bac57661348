#include "plan/plan_cost.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <glm/glm.hpp>

#include "uv/chart_packer.h"

namespace gi {

namespace {

// ---------------------------------------------------------------------------------------
// Calibration table. CPU seconds are user + sys of `gi-bake --methods <m> --preset <p>`
// (/usr/bin/time), one method per run, on cornell_box, spot_chamber and demo_level at preview
// and medium (docs/plan.md, "Calibration"): CPU time does not change when other jobs share
// the two cores, wall time does. Wall time on a quiet machine = the parallel part / 2 + the
// serial part; checked against the quiet wall times in docs/prm.md (spot chamber medium
// 6.0 s, demo level preview 2.9 s) and docs/prm.md's 0.93 s light-atlas preview re-bake of
// the demo level.
// ---------------------------------------------------------------------------------------

// Light atlas (gi/src/light_atlas): final shooting casts one shadow ray per (lit texel, VPL
// facing it); progressive refinement computes form-factor rows, about V^2 visibility tests
// per generation set; direct light casts one ray per (sample point, light point).
constexpr double kAtlasFinalFacing = 0.55;        // rays / (lit texels x VPLs): 0.45-0.65 measured
constexpr double kAtlasPropagationRaysPerV2 = 5;  // rays / VPL^2 over all generations: 4.4-6.6 measured
constexpr double kAtlasCpuPerFinalRay =
    2.0e-7;  // s; final shooting: demo_level medium 19.9 s / 97.7 M, spot_chamber medium 2.4 s / 12.1 M
constexpr double kAtlasCpuPerPropRay =
    2.2e-7;  // s; propagation incl. the shooting loop: cornell_box medium 1.26 s, ~5 M rays (serial)
constexpr double kAtlasCpuPerDirectRay = 1.0e-7;  // s; cornell_box preview (128 light points) minus the other terms
constexpr double kAtlasCpuOverhead = 0.05;        // s; layout, rasterization, files
// Final gather (texel_gather.h): every lit texel casts its kept and fresh rays (closest hit)
// and its direct-light shadow rays; the solve's iterations and the filter are lookups.
// Rays per texel: TexelGatherSettings' kept (solve_rays) and fresh (gather_rays) rays, one
// shadow ray per punctual or directional light, direct_samples per texel when area lights
// are sampled (gather_rays_per_texel below; a new per-texel ray count of the gather belongs there).
// The gather's fixed cost (layout, rasterization, the static scene, the VPLs for the runtime,
// files), serial: the Cornell box's quiet bakes at its preset densities (228-2388 texels) take
// 0.017 / 0.032 / 0.29 s against 0.004 / 0.013 / 0.28 s of rays (tools/plan-calibration.py,
// 29 Nov 2026), so ~0.015 s; 0.05 s overestimated them 2-3x.
constexpr double kGatherCpuOverhead = 0.015;
constexpr double kAtlasCpuPerGatherRay =
    2.3e-7;  // s; demo_level preview 7.9 M rays in 0.92 s wall, medium 59.6 M in 6.5 s (2 threads)
// A ray costs more in a larger scene once its BVH no longer stays in cache: flat from the spot
// chamber (24 triangles, 2.0e-7 s per ray at medium) to the demo level (~2300, 2.2e-7), then
// +3% per doubling of the triangles: Dabrovic Sponza (66k triangles, 5 doublings above) costs
// 1.15x per ray. (Fitted at +12% a doubling while the landings' sun rays were not counted as
// rays: their cost sat in Sponza's per-ray factor; with kLandingLightRaysPerFreshRay counting
// them, Sponza's quiet preview 30.1 s and medium-at-8 38.2 s are estimated 32.1 s and 36.5 s.)
constexpr double kAtlasCacheTriangles = 2048.0;
constexpr double kAtlasRayCostPerDoubling = 0.03;
// The landing reads' visibility rays (texel_landing.h; docs/light_atlas.md, "The hidden
// texels, third pass"): a fresh ray that lands closer than a texel, or on a texel whose sample
// was moved off its surface, checks whether each bilinear corner's sample sees the landing
// point. Counted per fresh ray (gi-bake --preset preview, 29 Nov 2026): Dabrovic Sponza 0.56
// (39.1 M for 69.3 M fresh rays, untextured, 8 texels/m), the Cornell box 0.83 (32 texels/m)
// and 0.38 (128 texels/m), the demo level 0.26, the spot chamber 0.25. Short (a texel or two),
// they cost nothing measurable in the small scenes (CPU s before / after them: Cornell box
// 128 texels/m high 9.59 / 9.25, demo level preview 2.34 / 2.26, tools/plan-calibration.py)
// but about a gather ray each in Sponza, whose quiet preview bake went from 18.7 s to 26-30 s
// (docs/light_atlas.md; without the kept rays' 9.8 M, its CPU time fell by 3.7 s). Modelled as
// gather-ray equivalents per fresh ray growing as the ray cost does, with the triangles'
// doublings above kAtlasCacheTriangles: 0.11 each, Sponza's 5 doublings 0.56.
constexpr double kVisibilityRaysPerFreshRayPerDoubling = 0.11;
// An emitter-sampled gather ray (TexelGatherSettings::emitter_rays, 32 in the preview and
// medium presets since the eighth session) costs about one cosine ray. The eighth session took
// 3.6 from Sponza's preview bake on 2 cores at load ~10 (44.4 CPU s without them, 77.3 s with);
// on quiet cores (ninth session) the medium settings at 8 texels/m took 29.0 s wall without
// them (29 Nov, docs/sweeps/light_atlas_sponza/speedup.md) and 29.6 s with 32 per texel, so
// the loaded CPU time was the load's, not the rays'.
// A landing nearer than a texel regathers with TexelGatherSettings::near_regather_rays rays of
// its own (docs/light_atlas.md, "Near landings regather at their point"). Counted in gather-ray
// equivalents per fresh ray and near ray: on Sponza at 8 texels/m, 4 near rays took the medium
// settings from 29.6 s to 33.0 s wall (quiet cores, ninth session), ~0.04 each. Scenes with
// fewer small charts and corners land near less often (the Cornell box at 128 texels/m: 3.9 s
// either way), so this overestimates them a little.
constexpr double kNearRegatherPerFreshRay = 0.04;
// Each ray of a regather below the first level (TexelGatherSettings::near_regather_depth,
// near_regather_deep_rays): Sponza at 8 texels/m, medium, 27.8 s -> 28.9 s with one ray at the
// second level, 32.3 s with four (quiet cores, fourteenth session): ~0.01 per ray and level.
constexpr double kNearDeepPerFreshRay = 0.01;
// LandingDirect::Punctual (the preview and medium presets): a landing reads the punctual and
// directional lights at its point, one shadow ray each (where a corner sees it). Per fresh ray
// and light, in gather-ray equivalents, from the quiet calibration of 30 Nov 2026 (docs/plan.md):
// the demo level's three point lights made its bakes 1.9x the estimate that counted them once
// per texel; the spot chamber's one spot 1.2x. 0.35 brings both to 0.89-1.01 (most landings
// are read at the point; a shadow ray is cheaper than a gather ray).
constexpr double kLandingLightRaysPerFreshRay = 0.35;

// PRM (gi/src/prm): every path node (virtual light) is connected to every pane texel facing
// it by one shadow ray; nodes = E x N_s x a / (1 - a) for a mean albedo a.
constexpr double kPrmFacing = 0.5;        // rays / (nodes x pane texels): 0.26 (cornell) - 0.68 (spot)
constexpr double kPrmCpuPerRay = 9.0e-8;  // s; measured 7.6e-8 (spot_chamber medium) to 1.05e-7 (demo_level medium)
constexpr double kPrmCpuOverhead = 0.03;  // s
constexpr double kPrmNodesFudge = 1.0;    // measured nodes / modelled nodes

// Texels: a chart of w x h metres at density d covers about (w d + 1)(h d + 1) x fill texels
// (conservative rasterization); the PRM pane adds the dilation rings around it.
constexpr double kPaneRings = 2.0;  // texels each side
constexpr int kAtlasPadding = 2;    // uv/atlas_layout.h default
constexpr int kAtlasMaxSize = 4096;

// Basis radiance fields (gi/src/brf): fitted to `gi-bake --scene assets/demo_level.gltf
// --methods brf --preset {preview,medium}` (3 meshes, 612 vertices): 0.37 / 1.16 CPU s
// measured (user + sys), 0.39 / 1.25 estimated. The field's rays all aim at a small object
// (coherent), about 6 M per CPU second; ~1 ns per SH multiply-add of the projection.
constexpr double kBrfCpuPerRay = 1.0 / 6.0e6;
constexpr double kBrfCpuPerMadd = 1.0e-9;

// Runtime bytes: the light atlas is an RGBA32F texture (light_atlas_lighting.cpp); PRM panes
// are half floats (6 bytes per texel and cluster) plus its own RGBA32F irradiance atlas.
constexpr double kAtlasTexelBytes = 16.0;
constexpr double kPaneTexelBytes = 6.0;
// Coarse PRM panes (pane_upsample.h, docs/prm.md "What Sponza's medium PRM holds"): the
// panes keep the texels inside the charts' footprints only, uploaded as RGB9E5 (4 bytes), and
// the upsampler holds 16 bytes per lit atlas texel and 8 per gutter-ring texel.
constexpr double kCoarsePaneTexelBytes = 4.0;
constexpr double kUpsampleBytesPerLitTexel = 16.0;
constexpr double kUpsampleBytesPerRingTexel = 8.0;

// Sparse PRM panes (gi/src/prm/prm_panes.h): the share of the dense panes' texels the kept
// blocks hold at a pane_threshold, the largest measured (docs/prm.md "Sparse panes"): a
// single room keeps the most, since every cluster lights every wall there (spot chamber,
// medium: 0.993 at 0 and 0.001, 0.989 at 0.01, 0.903 at 0.03). Held at its last value
// above the last measurement, so the estimate never claims a saving not measured.
double prm_stored_share(double threshold) {
  struct Point {
    double threshold, share;
  };
  // At 0 the dense bound: a tile no light reaches is rare in a closed level.
  constexpr Point kMeasured[] = {{0.0, 1.0}, {0.001, 0.993}, {0.01, 0.989}, {0.03, 0.903}};
  if (threshold <= kMeasured[0].threshold) return kMeasured[0].share;
  for (std::size_t i = 1; i < std::size(kMeasured); ++i)
    if (threshold <= kMeasured[i].threshold) {
      const Point &a = kMeasured[i - 1], &b = kMeasured[i];
      return a.share + (b.share - a.share) * (threshold - a.threshold) / (b.threshold - a.threshold);
    }
  return kMeasured[std::size(kMeasured) - 1].share;
}

// Directional light maps (gi/src/dlm): every photon casts 1 + a / (1 - a) rays for a mean
// albedo a (Russian roulette with the albedo), and every hit on a glossy texel after a bounce
// is splatted into ~(2r)^2 texels.
constexpr double kDlmCpuPerRay = 3.5e-7;  // s; incoherent rays + splats: see docs/dlm.md (calibration)
constexpr double kDlmCpuOverhead = 0.05;  // s; layout, rasterization, the splat normalizer, dilation
constexpr double kDlmTexelBytesPerDirection = 8.0;

double wall_seconds(double parallel_cpu, double serial_cpu) { return parallel_cpu / 2.0 + serial_cpu; }

// Doublings of a scene's `triangles` above kAtlasCacheTriangles (0 below).
double cache_doublings(std::size_t triangles) {
  return std::max(0.0, std::log2(static_cast<double>(triangles) / kAtlasCacheTriangles));
}

// The final gather's rays per lit texel in a scene of `triangles`: TexelGatherSettings' ray
// counts, the lights, and the landing reads' visibility rays of the fresh rays (in gather-ray
// equivalents, kVisibilityRaysPerFreshRayPerDoubling).
double gather_rays_per_texel(const TexelGatherSettings& g, const LightPointCount& lights, std::size_t triangles) {
  const double doublings = cache_doublings(triangles);
  // The adaptive passes (TexelGatherSettings::adaptive_share) repeat the fresh rays of a share of the texels.
  const int deep_rays = g.near_regather_deep_rays > 0 ? g.near_regather_deep_rays : g.near_regather_rays;
  const double near = g.near_regather_rays > 0 ? kNearRegatherPerFreshRay * g.near_regather_rays +
                                                     kNearDeepPerFreshRay * deep_rays * (g.near_regather_depth - 1)
                                               : 0.0;
  const double fresh =
      (g.gather_rays + g.emitter_rays) * (1.0 + near) * (1.0 + double{g.adaptive_share} * g.adaptive_passes);
  const double visibility = kVisibilityRaysPerFreshRayPerDoubling * doublings;
  const double landing_lights = g.landing_direct == TexelGatherSettings::LandingDirect::Punctual
                                    ? kLandingLightRaysPerFreshRay * (lights.punctual + lights.directional)
                                    : 0.0;
  return g.solve_rays + fresh * (1.0 + visibility + landing_lights) + lights.punctual + lights.directional +
         static_cast<double>(lights.sampled > 0 ? g.direct_samples : 0);
}

// CPU seconds per gather ray in a scene of `triangles` (kAtlasCacheTriangles above).
double gather_cpu_per_ray(std::size_t triangles) {
  return kAtlasCpuPerGatherRay * (1.0 + kAtlasRayCostPerDoubling * cache_doublings(triangles));
}

}  // namespace

AtlasTexelEstimate atlas_texels(const StaticSurfaceCensus& census, float texels_per_metre) {
  AtlasTexelEstimate out;
  const double d = texels_per_metre;
  std::vector<glm::ivec2> footprints;
  for (const ChartExtent& c : census.charts) {
    const double w = c.width_m * d, h = c.height_m * d;
    const double fill = w > 0.0 && h > 0.0 ? std::clamp(c.area_m2 * d * d / (w * h), 0.05, 1.0) : 1.0;
    out.lit_texels += fill * (w + 1.0) * (h + 1.0);
    out.pane_texels += fill * (w + 1.0 + 2.0 * kPaneRings) * (h + 1.0 + 2.0 * kPaneRings);
    footprints.emplace_back(static_cast<int>(std::ceil(w)) + 1, static_cast<int>(std::ceil(h)) + 1);
    out.footprint_texels += static_cast<double>(footprints.back().x) * footprints.back().y;
  }
  if (!footprints.empty()) {
    // The packer itself (cheap): footprints too large for the biggest atlas get the maximum.
    if (auto packing = pack_growing(footprints, kAtlasPadding, kAtlasMaxSize)) {
      out.width = packing->width, out.height = packing->height;
    } else {
      out.width = out.height = kAtlasMaxSize;
    }
  }
  return out;
}

BakeWork light_atlas_work(const StaticSurfaceCensus& census, const LightAtlasSettings& s,
                          const LightPointCount& lights) {
  BakeWork w;
  const AtlasTexelEstimate t = atlas_texels(census, s.texels_per_metre);
  if (s.final_pass == LightAtlasSettings::FinalPass::TexelGather) {
    w.rays = t.lit_texels * gather_rays_per_texel(s.gather, lights, census.triangles);
    w.units = w.rays;
    const double parallel = w.rays * gather_cpu_per_ray(census.triangles);
    w.cpu_seconds = parallel + kGatherCpuOverhead;
    w.bake_seconds = wall_seconds(parallel, kGatherCpuOverhead);
    w.runtime_bytes = static_cast<std::uint64_t>(static_cast<double>(t.width) * t.height * kAtlasTexelBytes);
    return w;
  }
  const double v = s.vpl_count;
  const double light_points =
      lights.punctual + lights.directional + static_cast<double>(lights.sampled) * s.area_light_samples;
  const double final_rays = kAtlasFinalFacing * t.lit_texels * v;
  const double prop_rays = s.bounces > 1 ? kAtlasPropagationRaysPerV2 * v * v : 0.0;
  const double direct_rays = 0.5 * v * s.samples_per_vpl * light_points + 4096.0 * lights.punctual;
  w.rays = final_rays + prop_rays + direct_rays;
  w.units = t.lit_texels * v;
  const double parallel = final_rays * kAtlasCpuPerFinalRay + direct_rays * kAtlasCpuPerDirectRay;
  const double serial = prop_rays * kAtlasCpuPerPropRay + kAtlasCpuOverhead;
  w.cpu_seconds = parallel + serial;
  w.bake_seconds = wall_seconds(parallel, serial);
  w.runtime_bytes = static_cast<std::uint64_t>(static_cast<double>(t.width) * t.height * kAtlasTexelBytes);
  return w;
}

BakeWork prm_work(const StaticSurfaceCensus& census, const PrmSettings& s, double* path_nodes) {
  BakeWork w;
  // Panes (and the bake's shadow rays) at the panes' density; the irradiance atlas at the
  // atlas's, plus, for coarse panes, the coarse sum's texture and the upsampler's taps.
  const AtlasTexelEstimate t = atlas_texels(census, pane_density(s));
  const AtlasTexelEstimate atlas = atlas_texels(census, s.texels_per_metre);
  const double a = std::clamp(census.albedo, 0.0, 0.95);
  const double nodes = kPrmNodesFudge * s.entry_points * static_cast<double>(s.splitting) * a / (1.0 - a);
  if (path_nodes) *path_nodes = nodes;
  w.rays = kPrmFacing * nodes * t.pane_texels;
  w.units = nodes;
  const double parallel = w.rays * kPrmCpuPerRay;
  w.cpu_seconds = parallel + kPrmCpuOverhead;
  w.bake_seconds = wall_seconds(parallel, kPrmCpuOverhead);
  const double output = static_cast<double>(atlas.width) * atlas.height * kAtlasTexelBytes;
  const double share = prm_stored_share(s.pane_threshold);
  if (!coarse_panes(s)) {
    w.runtime_bytes =
        static_cast<std::uint64_t>(static_cast<double>(s.clusters) * t.pane_texels * kPaneTexelBytes * share + output);
    return w;
  }
  // Coarse: the panes at the footprints, the coarse sum's texture, the upsampler's records.
  const double upsampling = static_cast<double>(t.width) * t.height * kAtlasTexelBytes +
                            atlas.lit_texels * kUpsampleBytesPerLitTexel +
                            (atlas.pane_texels - atlas.lit_texels) * kUpsampleBytesPerRingTexel;
  w.runtime_bytes = static_cast<std::uint64_t>(
      static_cast<double>(s.clusters) * t.footprint_texels * kCoarsePaneTexelBytes * share + output + upsampling);
  return w;
}

BakeWork brf_work(std::size_t vertex_count, std::size_t triangle_count, const PcaBasisSettings& basis,
                  const RadianceFieldSettings& field, int terms) {
  (void)triangle_count;
  BakeWork w;
  const double n = static_cast<double>(basis.basis) * terms;  // channels: a glossy mesh has one per (term, function)
  const double coefficients = static_cast<double>(field.sh_bands) * field.sh_bands;
  const double samples = static_cast<double>(field.spheres) * 6.0 * field.face_resolution * field.face_resolution;
  const double pca_rays = static_cast<double>(basis.lights) * static_cast<double>(vertex_count);
  const double field_rays = samples * field.directions;
  w.rays = pca_rays + field_rays;
  w.units = samples;
  const double parallel = w.rays * kBrfCpuPerRay + field_rays * n * coefficients * kBrfCpuPerMadd;
  w.cpu_seconds = parallel;
  w.bake_seconds = wall_seconds(parallel, 0.0);
  // Field (Iwasaki §4.3): spheres x 6 x res^2 points x K terms x N functions x SH
  // coefficients floats; basis: N values per vertex and the N x N inverse.
  const double nb = basis.basis;
  w.runtime_bytes = static_cast<std::uint64_t>(samples * n * coefficients * 4.0 +
                                               nb * static_cast<double>(vertex_count) * 4.0 + nb * nb * 4.0);
  return w;
}

BakeWork dlm_work(const StaticSurfaceCensus& glossy, double albedo, const AtlasTexelEstimate& atlas,
                  const DlmSettings& s, double* stored_texels, double* bytes_per_texel) {
  BakeWork w;
  const AtlasTexelEstimate t = atlas_texels(glossy, s.texels_per_metre);
  const double a = std::clamp(albedo, 0.0, 0.95);
  w.rays = static_cast<double>(s.photons) * (1.0 + a / (1.0 - a));
  w.units = static_cast<double>(s.photons);
  const double parallel = w.rays * kDlmCpuPerRay;
  w.cpu_seconds = parallel + kDlmCpuOverhead;
  w.bake_seconds = wall_seconds(parallel, kDlmCpuOverhead);
  const double per_texel = kDlmTexelBytesPerDirection * s.directions;
  // Stored texels: the glossy texels and one gutter ring around each chart.
  const double texels = t.lit_texels + (t.pane_texels - t.lit_texels) / (2.0 * kPaneRings);
  if (stored_texels) *stored_texels = texels;
  if (bytes_per_texel) *bytes_per_texel = per_texel;
  w.runtime_bytes =
      static_cast<std::uint64_t>(texels * per_texel + 4.0 * static_cast<double>(atlas.width) * atlas.height);
  return w;
}

namespace {

// Reflection probes (gi/src/reflection_probes): CPU seconds per capture ray (camera or shadow
// ray, material lookup, atlas read) and per prefilter sample, from the glossy_room bake at
// preview (docs/reflection_probes.md, "Costs").
constexpr double kProbeCpuPerRay = 1.0e-6;
constexpr double kProbeCpuPerPrefilterSample = 2.0e-8;

}  // namespace

BakeWork reflection_probes_work(std::size_t probes, const ReflectionProbeSettings& s, int light_points) {
  BakeWork w;
  const double texels = 6.0 * s.resolution * s.resolution * static_cast<double>(probes);
  const double rays_per_texel = static_cast<double>(s.supersample * s.supersample) * (1.0 + light_points);
  w.rays = texels * rays_per_texel;
  w.units = texels;
  const double parallel = w.rays * kProbeCpuPerRay + texels / 3.0 * s.prefilter_samples * kProbeCpuPerPrefilterSample;
  w.cpu_seconds = parallel;
  w.bake_seconds = wall_seconds(parallel, 0.0);
  // RGBA16F levels with their mips, R32F distances at kProbeDistanceScale x level 0's size, the boxes.
  const double distance_texels = texels * kProbeDistanceScale * kProbeDistanceScale;
  w.runtime_bytes =
      static_cast<std::uint64_t>(texels * 8.0 * 4.0 / 3.0 + distance_texels * 4.0 + 48.0 * static_cast<double>(probes));
  return w;
}

namespace {

// Antiradiance (gi/src/antiradiance; measured by gi-sweep on the corridor, docs/sweeps/
// antiradiance_corridor.csv, 0.4-0.8 m elements x 36-121 bins, and gi-bake on the demo level).
// Links per element and bin: 4.57 at 0.6-0.8 m on the corridor, 3.85 at 0.4 m, 3.77 on the
// demo level at preview (13259 elements, 3.2 M links), leaves linked regardless.
constexpr double kArLinksPerElementBin = 4.2;
// With the leaf links split (leaf_link_pieces > 0, the presets since issue 37) coplanar
// neighbours are no longer linked: 3.80 at 64 bins and 3.90 at 144 on the corridor (0.8 m,
// gi-sweep: 1.33 M / 3.07 M links of 5475 elements), 2.86 on the demo level at preview
// (gi-bake: 2.44 M links of 13331 elements, 3.12 M unsplit).
constexpr double kArSplitLinksPerElementBin = 3.3;
// Bake wall seconds per link (linking + the baseline solve at 8 iterations + the direct
// light), 2 threads shared: 0.55-0.65 us over the corridor grid (bake_s / links).
constexpr double kArSecondsPerLink = 6.0e-7;
constexpr double kArSecondsOverhead = 0.05;
// GPU bytes per link: the 8-byte record (sender, form factor) plus its share of the 16-byte
// (receiver, bin) runs (0.12 runs per link: 28.5 MB measured for 1.62 M links, 5475
// elements, 64 bins, of which 12.6 MB are the tables).
constexpr double kArGpuBytesPerLink = 9.8;
// antiradiance.bin: 4.8 bytes per link (zstd planes, AntiradianceIo test) + 72 per element
// and 12 per leaf.
constexpr double kArFileBytesPerLink = 4.8;
// Iterations of a solve to a residual tolerance (1e-3): 19 on the corridor at 0.8 m / 64 bins
// (docs/antiradiance.md, issue 37); at most the budget.
constexpr int kArConvergedIterations = 19;
// Near-door visibility on the corridor at medium (docs/antiradiance.md, issue 37; quiet
// machine, BM_NearVisibilityMoveAtMedium/pairs:4/reuse:1/warm:1/fast:2): with every one of
// its 2738 leaves a receiver (the medium budget), 3.75 M pairs, the baked pose's couplings
// 0.68 s (near_bake_ms), a door move's near update and solve 0.16 s; with the 1 m radius
// alone (863 receivers, 2.0 M pairs) 0.30 s and 0.11 s. ~0.05 us per point pair; a move ~0.25
// of the load. (The older 0.14 us had been measured under load 8-10.)
constexpr double kNearSecondsPerPointPair = 5.0e-8;
constexpr double kNearMoveFraction = 0.25;

}  // namespace

BakeWork near_visibility_work(std::size_t leaves, std::size_t receivers, const AntiradianceSettings& s,
                              double* move_seconds) {
  BakeWork w;
  const double l = static_cast<double>(leaves), r = static_cast<double>(std::min(receivers, leaves));
  const double pairs = r * (l - 1.0) - r * (r - 1.0) / 2.0;  // pairs with at least one receiver
  w.units = pairs;
  w.rays = pairs * std::max(1, s.near_visibility_point_pairs);
  w.cpu_seconds = w.rays * kNearSecondsPerPointPair;  // at load; nothing is baked
  // The receivers' rows, the transport's only table: per receiver and leaf a float coupling
  // and the kept visibility, a 16-bit word per 16 point pairs (close pairs draw 16).
  const double words = std::ceil(static_cast<double>(std::max(16, s.near_visibility_point_pairs)) / 16.0);
  w.runtime_bytes = static_cast<std::uint64_t>(r * l * (4.0 + 2.0 * words));
  if (move_seconds) *move_seconds = kNearMoveFraction * w.cpu_seconds;
  return w;
}

BakeWork antiradiance_work(std::size_t elements, std::size_t leaves, const AntiradianceSettings& s, double* links,
                           double* file_bytes) {
  BakeWork w;
  const double m = static_cast<double>(s.bins_per_side) * s.bins_per_side;
  const double n = static_cast<double>(elements), l = static_cast<double>(leaves);
  const double k = (s.leaf_link_pieces > 0 ? kArSplitLinksPerElementBin : kArLinksPerElementBin) * m * n;
  w.units = k;
  // The baseline solve is ~20% of it at 8 iterations (cpu_solve_ms / bake_s in the sweep).
  const int iterations = s.residual_tolerance > 0.0 ? std::min(std::max(1, s.iterations), kArConvergedIterations)
                                                    : std::max(1, s.iterations);
  w.cpu_seconds = k * kArSecondsPerLink * (0.8 + 0.2 * iterations / 8.0) + kArSecondsOverhead;
  w.bake_seconds = w.cpu_seconds;
  w.runtime_bytes = static_cast<std::uint64_t>(24.0 * m * (n + l) + kArGpuBytesPerLink * k);
  if (links) *links = k;
  if (file_bytes) *file_bytes = kArFileBytesPerLink * k + 72.0 * n + 12.0 * l;
  return w;
}

}  // namespace gi
