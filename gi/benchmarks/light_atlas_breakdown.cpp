// Where a gathered light atlas differs from the path tracer on a level (issue 35, "the
// floor on the whole lightmap"): the gather's parts (the sun's and the lights' direct light,
// the sky's, the indirect) and the path tracer's (gi::reference_atlas_irradiance at the very
// same texel samples) per texel, the error of the whole lightmap broken down by kind of texel
// (near a sun shadow edge, on a chart border, hidden, shading normal off the face, per
// material, per chart size). The truth is two path-traced atlases of different seeds: with
// r = (r1 + r2) / 2, sum (a - r)^2 - sum (r1 - r2)^2 / 4 estimates sum (a - t)^2 without the
// references' noise (of the direct light too, which their variance does not cover).
// A diagnosis program, not a benchmark: it prints a table.
//   light_atlas_breakdown SCENE.gltf [texels_per_metre=8] [spp=64] [preset=medium] [cache_dir=.]
// The scene is baked untextured under docs/real_level.md's sun and gradient sky; the two
// references are cached in cache_dir (keyed by density and spp; delete them after a change
// of the path tracer or of the texel placement).
// Environment: GI_BREAKDOWN_FILTER=r (filter radius, texels; 0 = the sweep's unfiltered
// run), GI_BREAKDOWN_SEEDS=2 (a second gather: the gather-noise and floor columns),
// GI_BREAKDOWN_NEAR_DEPTH=depth[:deep_rays] (the near regather's levels), GI_BREAKDOWN_DENOISE=passes,
// GI_BREAKDOWN_EMITTERS=rays, GI_BREAKDOWN_SOURCE=r and GI_BREAKDOWN_SOURCE_RIDGE=x (the denoiser's passes, the emitter
// rays, the source filter's radius in texels and its linear fit's ridge), GI_BREAKDOWN_WORST=N (the N worst texels),
// GI_BREAKDOWN_TEXEL=i,j (per texel: its normals and face, 16 rays and what they read, the path tracer there at 0, 1
// and all bounces), GI_BREAKDOWN_DENOISE_GRID=passes:sigma[:ridge],... (denoiser settings on one gather, a line each;
// ridge: the local linear fit's, absent: local mean).
#include <engine/gltf.h>
#include <engine/sun.h>
#include <gi/bake_input.h>
#include <gi/frame_truth.h>
#include <gi/reference.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/texel_gather.h"
#include "raytrace/atlas_reference.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"
#include "raytrace/texel_samples.h"
#include "real_level_lighting.h"
#include "sweep/atlas_split_truth.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace {

struct Sums {
  double err2 = 0.0, noise2 = 0.0, ref2 = 0.0, diff = 0.0, ref = 0.0, diff_direct = 0.0, diff_indirect = 0.0;
  double gather_noise2 = 0.0;  // sum |a - a'|^2 / 2 over a second gather of another seed: the gather's variance
  std::size_t n = 0;
  void add_second(const glm::dvec3& a, const glm::dvec3& a2) { gather_noise2 += 0.5 * glm::dot(a - a2, a - a2); }
  // The parts' differences (gather - mean of the references), summed over the channels.
  void add_parts(const glm::dvec3& direct, const glm::dvec3& indirect) {
    diff_direct += direct.x + direct.y + direct.z;
    diff_indirect += indirect.x + indirect.y + indirect.z;
  }
  void add(const glm::dvec3& a, const glm::dvec3& r1, const glm::dvec3& r2) {
    const glm::dvec3 r = 0.5 * (r1 + r2), d = a - r, nd = r1 - r2;
    err2 += glm::dot(d, d);
    noise2 += 0.25 * glm::dot(nd, nd);
    ref2 += glm::dot(r, r);
    diff += d.x + d.y + d.z;
    ref += r.x + r.y + r.z;
    ++n;
  }
  double truth_err2() const { return std::max(0.0, err2 - noise2); }
  // What is left of the error without the gather's own noise (needs a second gather).
  double floor_err2() const { return std::max(0.0, truth_err2() - gather_noise2); }
};

void row(const char* name, const Sums& s, double all_ref2) {
  if (s.n == 0) return;
  const double truth2 = std::max(1e-30, s.ref2 - s.noise2);
  std::printf("| %s | %zu | %.4f | %+.4f | %+.4f | %+.4f | %.4f | %.4f | %.4f | %.4f |\n", name, s.n,
              std::sqrt(s.truth_err2() / truth2), s.diff / s.ref, s.diff_direct / s.ref, s.diff_indirect / s.ref,
              std::sqrt(s.truth_err2() / all_ref2), std::sqrt(s.noise2 / std::max(1e-30, s.ref2)),
              std::sqrt(s.gather_noise2 / truth2), std::sqrt(s.floor_err2() / truth2));
}

bool load_cache(const std::filesystem::path& p, std::size_t n, std::vector<glm::vec3>& direct,
                std::vector<glm::vec3>& indirect) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return false;
  direct.resize(n);
  indirect.resize(n);
  f.read(reinterpret_cast<char*>(direct.data()), static_cast<std::streamsize>(n * sizeof(glm::vec3)));
  f.read(reinterpret_cast<char*>(indirect.data()), static_cast<std::streamsize>(n * sizeof(glm::vec3)));
  return static_cast<bool>(f);
}

void save_cache(const std::filesystem::path& p, const std::vector<glm::vec3>& direct,
                const std::vector<glm::vec3>& indirect) {
  std::ofstream f(p, std::ios::binary);
  f.write(reinterpret_cast<const char*>(direct.data()),
          static_cast<std::streamsize>(direct.size() * sizeof(glm::vec3)));
  f.write(reinterpret_cast<const char*>(indirect.data()),
          static_cast<std::streamsize>(indirect.size() * sizeof(glm::vec3)));
}

}  // namespace

// Long because it is one diagnosis read top to bottom: load, bake, references, the table.
int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.gltf [texels_per_metre] [spp] [preset] [cache_dir]\n", argv[0]);
    return 2;
  }
  const float density = argc > 2 ? std::strtof(argv[2], nullptr) : 8.0f;
  const int spp = argc > 3 ? std::atoi(argv[3]) : 64;
  const std::string preset = argc > 4 ? argv[4] : "medium";
  const std::filesystem::path cache = argc > 5 ? argv[5] : ".";
  auto loaded = gi_bench::load_untextured_under_sun_and_sky(argv[1]);
  if (!loaded) return std::fprintf(stderr, "%s\n", loaded.error().to_string().c_str()), 1;
  const engine::SceneAsset& asset = *loaded;
  const gi::BakeInput input = gi::bake_input_from(asset);

  gi::LightAtlasSettings s = gi::light_atlas_preset(preset).value();
  s.texels_per_metre = density;
  auto layout = gi::static_world_layout(input, density);
  if (!layout) return std::fprintf(stderr, "%s\n", layout.error().to_string().c_str()), 1;
  auto scene = gi::prepare_static_scene(input, *layout, gi::BakeLights::Static, gi::texel_placement(s));
  if (!scene) return std::fprintf(stderr, "%s\n", scene.error().to_string().c_str()), 1;
  gi::ThreadPool pool(2);
  gi::TexelGatherSettings g = s.gather;
  g.seed = s.seed;
  // GI_BREAKDOWN_FILTER=r: another filter radius (texels) than the preset's; 0 is the sweep's unfiltered run.
  if (const char* r = std::getenv("GI_BREAKDOWN_FILTER")) g.filter_radius_texels = std::strtof(r, nullptr);
  // GI_BREAKDOWN_DENOISE=passes, GI_BREAKDOWN_SOURCE=r: the denoiser's passes and the source filter's radius.
  if (const char* d = std::getenv("GI_BREAKDOWN_DENOISE")) g.denoise_passes = std::atoi(d);
  if (const char* e = std::getenv("GI_BREAKDOWN_EMITTERS")) g.emitter_rays = std::atoi(e);
  if (const char* r = std::getenv("GI_BREAKDOWN_SOURCE")) g.source_filter_radius_texels = std::strtof(r, nullptr);
  if (const char* r = std::getenv("GI_BREAKDOWN_SOURCE_RIDGE")) g.source_filter_slope_ridge = std::strtof(r, nullptr);
  // GI_BREAKDOWN_NEAR=rays,texels: landings nearer than `texels` regather with `rays` rays.
  if (const char* r = std::getenv("GI_BREAKDOWN_NEAR")) {
    g.near_regather_rays = std::atoi(r);
    if (const char* c = std::strchr(r, ',')) g.near_regather_texels = std::strtof(c + 1, nullptr);
  }
  // GI_BREAKDOWN_NEAR_DEPTH=depth[:deep_rays]: the regather's levels and the rays below the first.
  if (const char* d = std::getenv("GI_BREAKDOWN_NEAR_DEPTH")) {
    char* rest = nullptr;
    g.near_regather_depth = static_cast<int>(std::strtol(d, &rest, 10));
    if (*rest == ':') g.near_regather_deep_rays = static_cast<int>(std::strtol(rest + 1, nullptr, 10));
  }
  // GI_BREAKDOWN_DENOISE_GRID=passes:sigma[:ridge],...: the gathers once, unfiltered, then each
  // denoiser setting on copies of them, one line each (the whole lightmap and the
  // indirect-dominated texels), instead of the table.
  const char* denoise_grid = std::getenv("GI_BREAKDOWN_DENOISE_GRID");
  g.part_only = denoise_grid != nullptr;
  auto gathered = gi::gather_atlas(*scene, *layout, g, pool);
  if (!gathered) return std::fprintf(stderr, "%s\n", gathered.error().to_string().c_str()), 1;
  // GI_BREAKDOWN_SEEDS=2: a second gather of another seed; the two differ by the gather's noise,
  // so the "floor" column (error without that noise) is its bias and reconstruction error.
  std::optional<gi::TexelGatherResult> second;
  if (const char* seeds = std::getenv("GI_BREAKDOWN_SEEDS"); seeds && std::atoi(seeds) >= 2) {
    g.seed = s.seed + 1;
    auto again = gi::gather_atlas(*scene, *layout, g, pool);
    if (!again) return std::fprintf(stderr, "%s\n", again.error().to_string().c_str()), 1;
    second = std::move(again).value();
  }
  const gi::AtlasTexels& tx = scene->texels;
  const std::size_t n = tx.valid.size();

  std::vector<glm::vec3> rd[2], ri[2];
  for (int k = 0; k < 2; ++k) {
    const auto file = cache / ("breakdown_ref_" + std::to_string(static_cast<int>(density * 100)) + "_" +
                               std::to_string(spp) + "_" + std::to_string(k) + ".bin");
    if (load_cache(file, n, rd[k], ri[k])) continue;
    auto truth = gi::reference_atlas_irradiance(
        input, tx,
        {.samples_per_pixel = spp, .max_bounces = -1, .seed = 1000u + static_cast<unsigned>(k), .threads = 2});
    if (!truth) return std::fprintf(stderr, "%s\n", truth.error().to_string().c_str()), 1;
    rd[k] = truth->direct;
    ri[k] = truth->indirect;
    save_cache(file, rd[k], ri[k]);
  }

  if (denoise_grid) {
    for (const char* e = denoise_grid; e && *e; e = std::strchr(e, ',') ? std::strchr(e, ',') + 1 : nullptr) {
      gi::TexelGatherSettings f = g;
      char* rest = nullptr;
      f.denoise_passes = static_cast<int>(std::strtol(e, &rest, 10));
      f.denoise_sigma = std::strtof(rest + 1, &rest);
      if (*rest == ':') f.denoise_slope_ridge = std::strtof(rest + 1, &rest);
      f.part_only = false;
      gi::TexelGatherResult a = *gathered, b = second ? *second : *gathered;
      if (!gi::filter_gathered(*scene, *layout, f, pool, a) || !gi::filter_gathered(*scene, *layout, f, pool, b))
        return std::fprintf(stderr, "filter_gathered failed\n"), 1;
      Sums whole, dominated;
      for (std::size_t i = 0; i < n; ++i) {
        if (!scene->texels.valid[i]) continue;
        const glm::dvec3 va(a.direct[i] + a.baked_direct[i] + a.indirect[i]),
            vb(b.direct[i] + b.baked_direct[i] + b.indirect[i]);
        const glm::dvec3 r1(rd[0][i] + ri[0][i]), r2(rd[1][i] + ri[1][i]);
        whole.add(va, r1, r2), whole.add_second(va, vb);
        const glm::dvec3 rim = 0.5 * glm::dvec3(ri[0][i] + ri[1][i]), rm = 0.5 * (r1 + r2);
        if (gi::is_indirect_dominated(rim.x + rim.y + rim.z, rm.x + rm.y + rm.z))
          dominated.add(va, r1, r2), dominated.add_second(va, vb);
      }
      const auto rel = [](const Sums& x, double e2) { return std::sqrt(e2 / std::max(1e-30, x.ref2 - x.noise2)); };
      std::printf(
          "denoise %d passes, sigma %.2f, ridge %.2f: whole %.4f (noise %.4f, floor %.4f, bias %+.4f); "
          "indirect-dominated %.4f (noise %.4f, floor %.4f, bias %+.4f)\n",
          f.denoise_passes, static_cast<double>(f.denoise_sigma), static_cast<double>(f.denoise_slope_ridge),
          rel(whole, whole.truth_err2()), rel(whole, whole.gather_noise2), rel(whole, whole.floor_err2()),
          whole.diff / whole.ref, rel(dominated, dominated.truth_err2()), rel(dominated, dominated.gather_noise2),
          rel(dominated, dominated.floor_err2()), dominated.diff / dominated.ref);
    }
    return 0;
  }

  // The sun's unshadowed irradiance at each texel, to find its shadow edges.
  const glm::vec3 to_sun = -glm::normalize(glm::vec3(0.25f, -1.0f, 0.15f));
  std::vector<float> lit(n, -1.0f);  // fraction of the unshadowed sun the gather sees
  for (std::size_t i = 0; i < n; ++i) {
    if (!tx.valid[i]) continue;
    const float c = glm::dot(tx.normal[i], to_sun);
    lit[i] = c > 0.05f ? gathered->direct[i].y / (650.0f * c) : -1.0f;
  }
  // Texel i's triangle, and its face turned to the side of the texel's normal.
  const auto own_triangle = [&](std::size_t i) -> const gi::ShadingTriangle& {
    return scene->index
        .triangles[scene->index.instance_first[scene->static_instance[static_cast<std::size_t>(tx.mesh[i])]] +
                   static_cast<std::uint32_t>(tx.triangle[i])];
  };
  const auto texel_face = [&](std::size_t i) {
    const glm::vec3 f = own_triangle(i).face_normal;
    return glm::dot(f, tx.normal[i]) < 0.0f ? -f : f;
  };
  // Texels sandwiched between their own surface and another a few mm off it (overlapping
  // geometry): at least half of 16 cosine rays land within 2 cm.
  std::vector<std::uint8_t> sandwiched(n, 0);
  pool.parallel_for(n, [&](std::size_t i) {
    if (!tx.valid[i]) return;
    const glm::vec3 face = texel_face(i);
    const glm::vec3 origin = gi::offset_ray_origin(tx.position[i], face);
    int close = 0;
    for (int r = 0; r < 16; ++r) {
      const glm::vec3 wi = gi::sample_cosine_hemisphere(face, (static_cast<float>(r) + 0.5f) / 16.0f,
                                                        std::fmod(0.618034f * static_cast<float>(r), 1.0f));
      close += scene->caster->intersect(gi::Ray{origin, 0.0f, wi, 0.02f}).valid() ? 1 : 0;
    }
    sandwiched[i] = close >= 8 ? 1 : 0;
  });
  Sums all, total_direct, total_indirect;
  std::map<std::string, Sums> by;
  std::map<int, Sums> by_material, by_chart;
  std::map<std::string, Sums> by_dominated;
  // Per texel, for GI_BREAKDOWN_WORST_OF: 1 hidden, 2 sandwiched, 4 thin chart, 8 chart border,
  // 16 indirect-dominated.
  std::vector<std::uint8_t> kinds(n, 0);
  for (int y = 0; y < tx.height; ++y)
    for (int x = 0; x < tx.width; ++x) {
      const std::size_t i = tx.index(x, y);
      if (!tx.valid[i]) continue;
      const glm::dvec3 a_d(gathered->direct[i] + gathered->baked_direct[i]), a_i(gathered->indirect[i]);
      const glm::dvec3 a = a_d + a_i;
      const glm::dvec3 r1 = glm::dvec3(rd[0][i] + ri[0][i]), r2 = glm::dvec3(rd[1][i] + ri[1][i]);
      const glm::dvec3 dd = a_d - 0.5 * glm::dvec3(rd[0][i] + rd[1][i]),
                       di = a_i - 0.5 * glm::dvec3(ri[0][i] + ri[1][i]);
      const glm::dvec3 a2 = second ? glm::dvec3(second->direct[i] + second->baked_direct[i] + second->indirect[i]) : a;
      const auto into = [&](Sums& sums) {
        sums.add(a, r1, r2);
        sums.add_parts(dd, di);
        sums.add_second(a, a2);
      };
      into(all);
      total_direct.add(a_d, glm::dvec3(rd[0][i]), glm::dvec3(rd[1][i]));
      total_indirect.add(a_i, glm::dvec3(ri[0][i]), glm::dvec3(ri[1][i]));
      bool border = false, edge = false;
      for (int k = 0; k < 9; ++k) {
        const int nx = x + k % 3 - 1, ny = y + k / 3 - 1;
        if (nx < 0 || ny < 0 || nx >= tx.width || ny >= tx.height || !tx.valid[tx.index(nx, ny)] ||
            tx.chart[tx.index(nx, ny)] != tx.chart[i]) {
          border = true;
          continue;
        }
        const float l = lit[tx.index(nx, ny)];
        if (lit[i] >= 0.0f && l >= 0.0f && std::fabs(l - lit[i]) > 0.2f) edge = true;
      }
      const bool penumbra = lit[i] > 0.02f && lit[i] < 0.98f;
      const std::string kind = gathered->hidden[i] ? "hidden (back faces)"
                               : edge || penumbra  ? "sun shadow edge"
                               : border            ? "chart border"
                               : lit[i] >= 0.98f   ? "sunlit interior"
                               : glm::length(gathered->baked_direct[i]) > 0.0f && glm::length(a_i) == 0.0
                                   ? "sky only"
                                   : "shade interior";
      into(by[kind]);
      const gi::ShadingTriangle& tri = own_triangle(i);
      into(by[glm::dot(tri.face_normal, tx.normal[i]) < 0.996f ? "normal > 5 deg off face" : "normal on face"]);
      into(by_material[static_cast<int>(tri.material)]);
      const glm::ivec2 sz = layout->charts[static_cast<std::size_t>(tx.chart[i])].size;
      into(by_chart[sz.x * sz.y <= 16 ? 16 : sz.x * sz.y <= 64 ? 64 : sz.x * sz.y <= 256 ? 256 : 1 << 30]);
      // The measure, the sweep's definition: texels whose truth total is lit and at least
      // 80% indirect (texels the truth leaves dark were counted here before, not in the sweep).
      const glm::dvec3 ri_mean = 0.5 * glm::dvec3(ri[0][i] + ri[1][i]), r_mean = 0.5 * (r1 + r2);
      const bool thin = std::min(sz.x, sz.y) <= 4;  // the footprint includes the 1-texel rims
      const bool dominated =
          gi::is_indirect_dominated(ri_mean.x + ri_mean.y + ri_mean.z, r_mean.x + r_mean.y + r_mean.z);
      kinds[i] = static_cast<std::uint8_t>((gathered->hidden[i] ? 1 : 0) | (sandwiched[i] ? 2 : 0) | (thin ? 4 : 0) |
                                           (border ? 8 : 0) | (dominated ? 16 : 0));
      if (dominated) {
        into(by_dominated["all"]);
        into(by_dominated[gathered->hidden[i] ? "hidden" : border ? "chart border" : "chart interior"]);
        if (thin) into(by_dominated["thin chart (<= 4 texels across)"]);
        if (sandwiched[i]) into(by_dominated["sandwiched (half the rays land within 2 cm)"]);
        if (thin && !sandwiched[i]) into(by_dominated["thin chart, not sandwiched"]);
        into(by_dominated[sz.x * sz.y <= 64 ? "chart <= 64 texels" : "chart > 64 texels"]);
        into(by_dominated[glm::dot(tri.face_normal, tx.normal[i]) < 0.996f ? "normal > 5 deg off face"
                                                                           : "normal on face"]);
      }
    }
  // GI_BREAKDOWN_TEXEL=i: 16 rays from texel i, where they land and the texel the atlas reads there.
  // Several texels: GI_BREAKDOWN_TEXEL=i,j,k. Also where a ray towards the sun's centre stops.
  for (const char* probe = std::getenv("GI_BREAKDOWN_TEXEL"); probe && *probe;
       probe = std::strchr(probe, ',') ? std::strchr(probe, ',') + 1 : nullptr) {
    const std::size_t i = std::strtoul(probe, nullptr, 10);
    const gi::ShadingTriangle& own = own_triangle(i);
    const glm::vec3 face = texel_face(i);
    const glm::vec3 origin = gi::offset_ray_origin(tx.position[i], face);
    const gi::Hit sun_hit = scene->caster->intersect(gi::Ray{origin, 0.0f, to_sun});
    // The path tracer at the texel's sample with 0, 1 and all bounces: where its light comes from.
    for (const int bounces : {0, 1, -1}) {
      const gi::SurfacePoint point{.position_m = tx.position[i], .normal = tx.normal[i], .face_normal = face};
      auto pt = gi::reference_irradiance(input, std::span<const gi::SurfacePoint>(&point, 1),
                                         {.samples_per_pixel = 256, .max_bounces = bounces, .seed = 9, .threads = 2});
      if (pt)
        std::printf(
            "texel %zu: path tracer, %d bounces: direct %.1f indirect %.1f (triangle's own face_normal.y %.3f)\n", i,
            bounces, static_cast<double>(pt->direct[0].y), static_cast<double>(pt->indirect[0].y),
            static_cast<double>(own.face_normal.y));
    }
    std::printf(
        "texel %zu: p (%.4f %.4f %.4f) normal (%.3f %.3f %.3f) face (%.3f %.3f %.3f) sun cos %.3f / face %.3f, "
        "towards the sun: %s t %.4f\n",
        i, static_cast<double>(tx.position[i].x), static_cast<double>(tx.position[i].y),
        static_cast<double>(tx.position[i].z), static_cast<double>(tx.normal[i].x), static_cast<double>(tx.normal[i].y),
        static_cast<double>(tx.normal[i].z), static_cast<double>(face.x), static_cast<double>(face.y),
        static_cast<double>(face.z), static_cast<double>(glm::dot(tx.normal[i], to_sun)),
        static_cast<double>(glm::dot(face, to_sun)), sun_hit.valid() ? "hit" : "sky", static_cast<double>(sun_hit.t));
    std::printf("texel %zu: gather direct %.1f + %.1f indirect %.1f, moved %d\n", i,
                static_cast<double>(gathered->direct[i].y), static_cast<double>(gathered->baked_direct[i].y),
                static_cast<double>(gathered->indirect[i].y),
                glm::abs(glm::dot(tx.position[i] - own.p0, own.face_normal)) > 1e-4f ? 1 : 0);
    for (int r = 0; r < 16; ++r) {
      const glm::vec3 wi = gi::sample_cosine_hemisphere(tx.normal[i], (static_cast<float>(r) + 0.5f) / 16.0f,
                                                        std::fmod(0.618034f * static_cast<float>(r), 1.0f));
      const gi::Hit h = scene->caster->intersect(gi::Ray{origin, 0.0f, wi});
      if (!h.valid()) {
        std::printf("ray %d: sky\n", r);
        continue;
      }
      const gi::ShadingTriangle& tri = scene->index.triangles[scene->triangle_of(h)];
      const glm::vec3 p = tri.p0 + h.barycentric.x * tri.e1 + h.barycentric.y * tri.e2;
      const gi::AtlasMeshUv& mu = layout->meshes[h.instance];
      const std::uint32_t* idx = &mu.indices[3u * h.primitive];
      const glm::vec2 uv = (1.0f - h.barycentric.x - h.barycentric.y) * mu.uv1[idx[0]] +
                           h.barycentric.x * mu.uv1[idx[1]] + h.barycentric.y * mu.uv1[idx[2]];
      const std::size_t j = tx.index(std::min(static_cast<int>(uv.x * static_cast<float>(tx.width)), tx.width - 1),
                                     std::min(static_cast<int>(uv.y * static_cast<float>(tx.height)), tx.height - 1));
      std::printf("ray %d: t %.3f %s hit (%.3f %.3f %.3f) texel %zu valid %d at (%.3f %.3f %.3f) total %.1f\n", r,
                  static_cast<double>(h.t), glm::dot(tri.face_normal, wi) < 0.0f ? "front" : "back",
                  static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z), j, tx.valid[j],
                  static_cast<double>(tx.position[j].x), static_cast<double>(tx.position[j].y),
                  static_cast<double>(tx.position[j].z),
                  static_cast<double>(gathered->direct[j].y + gathered->baked_direct[j].y + gathered->indirect[j].y));
      // What covers the landing point: a ray straight off its side, and one to the sun.
      const glm::vec3 side = glm::dot(tri.face_normal, wi) < 0.0f ? tri.face_normal : -tri.face_normal;
      const gi::Hit up = scene->caster->intersect(gi::Ray{gi::offset_ray_origin(p, side), 0.0f, side});
      const gi::Hit sun = scene->caster->intersect(gi::Ray{gi::offset_ray_origin(p, side), 0.0f, to_sun});
      std::printf("    off its side: %s t %.4f; to the sun: %s t %.4f\n", up.valid() ? "hit" : "sky",
                  static_cast<double>(up.t), sun.valid() ? "hit" : "sky", static_cast<double>(sun.t));
      if (r < 3) {
        const float bu = h.barycentric.x, bv = h.barycentric.y;
        glm::vec3 sn = glm::normalize((1.0f - bu - bv) * tri.n0 + bu * tri.n1 + bv * tri.n2);
        if (glm::dot(sn, side) < 0.0f) sn = -sn;
        for (const glm::vec3& nn : {sn, side}) {
          const gi::SurfacePoint sp{.position_m = p, .normal = nn, .face_normal = side};
          auto pt = gi::reference_irradiance(input, std::span<const gi::SurfacePoint>(&sp, 1),
                                             {.samples_per_pixel = 256, .max_bounces = 0, .seed = 9, .threads = 2});
          if (pt)
            std::printf("    path tracer at the landing, normal (%.2f %.2f %.2f): direct %.1f\n",
                        static_cast<double>(nn.x), static_cast<double>(nn.y), static_cast<double>(nn.z),
                        static_cast<double>(pt->direct[0].y));
        }
      }
    }
  }
  // GI_BREAKDOWN_WORST=N: the N texels of the largest error, one line each.
  // GI_BREAKDOWN_WORST_OF=bits: only texels with all these kind bits (see `kinds`).
  if (const char* worst = std::getenv("GI_BREAKDOWN_WORST")) {
    const char* of = std::getenv("GI_BREAKDOWN_WORST_OF");
    const auto mask = static_cast<std::uint8_t>(of ? std::atoi(of) : 0);
    std::vector<std::pair<double, std::size_t>> err;
    for (std::size_t i = 0; i < n; ++i)
      if (tx.valid[i] && (kinds[i] & mask) == mask) {
        const double a =
            static_cast<double>(gathered->direct[i].y + gathered->baked_direct[i].y + gathered->indirect[i].y);
        const double r = 0.5 * static_cast<double>(rd[0][i].y + ri[0][i].y + rd[1][i].y + ri[1][i].y);
        err.emplace_back(std::fabs(a - r), i);
      }
    std::sort(err.rbegin(), err.rend());
    for (std::size_t k = 0; k < std::min<std::size_t>(err.size(), std::strtoul(worst, nullptr, 10)); ++k) {
      const std::size_t i = err[k].second;
      std::printf(
          "texel %zu (%d, %d) chart %d kinds %d hidden %d p (%.3f %.3f %.3f) n (%.3f %.3f %.3f): gather direct %.2f + "
          "%.2f "
          "indirect %.2f; path tracer direct %.2f / %.2f indirect %.2f / %.2f\n",
          i, static_cast<int>(i % static_cast<std::size_t>(tx.width)),
          static_cast<int>(i / static_cast<std::size_t>(tx.width)), tx.chart[i], kinds[i], gathered->hidden[i],
          static_cast<double>(tx.position[i].x), static_cast<double>(tx.position[i].y),
          static_cast<double>(tx.position[i].z), static_cast<double>(tx.normal[i].x),
          static_cast<double>(tx.normal[i].y), static_cast<double>(tx.normal[i].z),
          static_cast<double>(gathered->direct[i].y), static_cast<double>(gathered->baked_direct[i].y),
          static_cast<double>(gathered->indirect[i].y), static_cast<double>(rd[0][i].y),
          static_cast<double>(rd[1][i].y), static_cast<double>(ri[0][i].y), static_cast<double>(ri[1][i].y));
    }
  }
  std::printf("%s at %.1f texels/m, preset %s, truth 2 x %d spp\n", argv[1], static_cast<double>(density),
              preset.c_str(), spp);
  std::printf(
      "| texels | n | rel err vs truth | bias | of it direct | of it indirect | share of the whole error | ref noise "
      "| gather noise | floor |\n|---|---|---|---|---|---|---|---|---|---|\n");
  row("all (total)", all, all.ref2 - all.noise2);
  row("direct part (sun + sky)", total_direct, all.ref2 - all.noise2);
  row("indirect part", total_indirect, all.ref2 - all.noise2);
  for (const auto& [k, v] : by) row(k.c_str(), v, all.ref2 - all.noise2);
  for (const auto& [k, v] : by_chart)
    row(("chart <= " + std::to_string(k) + " texels").c_str(), v, all.ref2 - all.noise2);
  for (const auto& [k, v] : by_material) row(("material " + std::to_string(k)).c_str(), v, all.ref2 - all.noise2);
  for (const auto& [k, v] : by_dominated) row(("indirect-dominated: " + k).c_str(), v, all.ref2 - all.noise2);
  return 0;
}
