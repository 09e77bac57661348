#include "light_atlas/texel_gather.h"

#include <engine/sky.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>

#include "core/color.h"
#include "core/random.h"
#include "core/stopwatch.h"
#include "light_atlas/atlas_denoise.h"
#include "light_atlas/texel_cells.h"
#include "light_atlas/texel_direct.h"
#include "light_atlas/texel_emitters.h"
#include "light_atlas/texel_filter.h"
#include "light_atlas/texel_landing.h"
#include "light_atlas/texel_sampling.h"
#include "light_atlas/texel_table.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"
#include "uv/atlas_dilation.h"

namespace gi {
namespace {

using Clock = std::chrono::steady_clock;

constexpr float kPi = std::numbers::pi_v<float>;
// A texel whose kept rays see back faces this often lies inside or under geometry; the
// filter neither reads nor smooths it.
constexpr float kHiddenBackFraction = 0.1f;

// The rays of a texel cast together before any lands (land_rays).
constexpr std::size_t kRayBatch = 32;

// Item ids of the four random streams of a texel.
constexpr std::uint64_t kDirectStream = 0, kSolveStream = 1, kGatherStream = 2, kEmitterStream = 3;
std::uint64_t stream_id(std::uint64_t texel, std::uint64_t stream) { return texel * 4 + stream; }

engine::Status validate(const TexelGatherSettings& s) {
  const auto bad = [](const std::string& what) { return engine::invalid_request("texel gather settings: " + what); };
  if (s.direct_samples < 1 || s.direct_samples > 65536) return bad("direct_samples is outside 1..65536");
  if (s.solve_rays < 1 || s.solve_rays > 65536) return bad("solve_rays is outside 1..65536");
  if (s.gather_rays < 0 || s.gather_rays > 1 << 20) return bad("gather_rays is outside 0..2^20");
  if (s.emitter_rays < 0 || s.emitter_rays > 1 << 20) return bad("emitter_rays is outside 0..2^20");
  if (s.bounces < 1 || s.bounces > 1024) return bad("bounces is outside 1..1024");
  if (!(s.filter_radius_texels >= 0.0f) || s.filter_radius_texels > 16.0f)
    return bad("filter_radius_texels is outside [0, 16]");
  if (s.denoise_passes < 0 || s.denoise_passes > 8) return bad("denoise_passes is outside 0..8");
  if (!(s.denoise_sigma > 0.0f) || s.denoise_sigma > 1000.0f) return bad("denoise_sigma is outside (0, 1000]");
  if (!(s.denoise_outlier_sigmas >= 0.0f) || s.denoise_outlier_sigmas > 1000.0f)
    return bad("denoise_outlier_sigmas is outside [0, 1000]");
  if (!(s.denoise_slope_ridge <= 1e6f)) return bad("denoise_slope_ridge is NaN or above 1e6");
  if (!(s.source_filter_slope_ridge <= 1e6f)) return bad("source_filter_slope_ridge is NaN or above 1e6");
  if (!(s.source_filter_radius_texels <= 16.0f)) return bad("source_filter_radius_texels is above 16 (or NaN)");
  if (s.near_regather_rays < 0 || s.near_regather_rays > 4096) return bad("near_regather_rays is outside 0..4096");
  if (s.near_regather_depth < 1 || s.near_regather_depth > 8) return bad("near_regather_depth is outside 1..8");
  if (s.near_regather_deep_rays < 0 || s.near_regather_deep_rays > 4096)
    return bad("near_regather_deep_rays is outside 0..4096");
  if (!(s.near_regather_texels >= 0.0f) || s.near_regather_texels > 64.0f)
    return bad("near_regather_texels is outside [0, 64]");
  if (!(s.adaptive_share >= 0.0f) || s.adaptive_share > 1.0f) return bad("adaptive_share is outside [0, 1]");
  if (s.adaptive_passes < 1 || s.adaptive_passes > 16) return bad("adaptive_passes is outside 1..16");
  return {};
}

float max_abs(const glm::vec3& v) { return std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z))); }

// The sky's radiance along a ray that escapes in direction wi (engine/sky.h).
glm::vec3 sky_along(const StaticBakeScene& b, const glm::vec3& wi) {
  return engine::sky_radiance(b.scene.sky_radiance, b.scene.sky_gradient, wi);
}

// What steps 2-3 hand each other.
struct KeptRays {
  std::size_t per_texel = 0;
  std::vector<std::uint32_t> land;   // work item w's ray r lands at land[w * per_texel + r]
  std::vector<glm::vec3> sky;        // per atlas texel: the sky's direct irradiance from the kept rays
  std::vector<std::uint8_t> hidden;  // per atlas texel
};

// Step 2's casting: `solve_rays` stratified cosine rays per texel, each kept as the texel it
// lands on. The rays that escape see the sky: with cosine sampling E = pi / N x the sum of
// the sky's radiance over the escaping rays (the sky's direct light, shadowed by the level).
bool cast_kept_rays(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const TexelGatherSettings& s,
                    ThreadPool& pool, const ProgressCallback& progress, std::vector<std::uint64_t>& rays_of,
                    KeptRays& k) {
  const AtlasTexels& tx = b.texels;
  const std::size_t ns = static_cast<std::size_t>(s.solve_rays);
  k.per_texel = ns;
  k.land.assign(t.work.size() * ns, kDark);
  k.sky.assign(tx.valid.size(), glm::vec3(0.0f));
  k.hidden.assign(tx.valid.size(), 0);
  return pool.parallel_for_with_progress(t.work.size(), progress, [&](std::size_t w) {
    const std::uint32_t i = t.work[w];
    Pcg32 rng = Pcg32::for_item(s.seed, stream_id(i, kSolveStream));
    const float shift_y = rng.next_float();  // drawn first: see random.h
    const glm::vec2 shift(rng.next_float(), shift_y);
    const glm::vec3 origin = offset_ray_origin(tx.position[i], t.face[i]);
    std::size_t back = 0;
    glm::vec3 sky_seen(0.0f);
    // Cast kRayBatch at a time (land_rays), read in the rays' order.
    std::array<Ray, kRayBatch> batch;
    std::array<std::uint32_t, kRayBatch> ray_of, landed;
    for (std::size_t first = 0; first < ns; first += kRayBatch) {
      std::size_t m = 0;
      for (std::size_t r = first; r < std::min(ns, first + kRayBatch); ++r) {
        const glm::vec2 u = hammersley(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(ns), shift);
        const glm::vec3 wi = sample_cosine_hemisphere(tx.normal[i], u.x, u.y);
        if (glm::dot(wi, t.face[i]) <= 0.0f) continue;  // below the surface: dark
        batch[m] = Ray{origin, 0.0f, wi}, ray_of[m++] = static_cast<std::uint32_t>(r);
      }
      rays_of[w] += m;
      landings(b, lt, t, std::span(batch).first(m), t.face[i], std::span(landed).first(m));
      for (std::size_t j = 0; j < m; ++j) {
        k.land[w * ns + ray_of[j]] = landed[j];
        if (landed[j] == kSky) sky_seen += sky_along(b, batch[j].direction);
        back += landed[j] == kBack;
      }
    }
    k.hidden[i] = static_cast<float>(back) > kHiddenBackFraction * static_cast<float>(ns) ? 1 : 0;
    k.sky[i] = kPi * sky_seen / static_cast<float>(ns);
  });
}

// Step 2's iteration: E_i+1 = T(E_d + E_i) over the kept rays until a bounce adds less than
// 1e-4 of the total. `emitted` is the direct light every texel reflects (E_d). Returns the
// iterations run.
int solve_kept_rays(const TexelTable& t, const KeptRays& k, const std::vector<glm::vec3>& emitted, int bounces,
                    ThreadPool& pool, std::vector<glm::vec3>& e) {
  const std::size_t n = e.size(), ns = k.per_texel;
  std::vector<glm::vec3> reflected(n, glm::vec3(0.0f)), next(n, glm::vec3(0.0f));
  int iterations = 0;
  for (int it = 0; it < bounces; ++it) {
    for (std::uint32_t i : t.work) reflected[i] = t.albedo[i] * (emitted[i] + e[i]);
    pool.parallel_for(
        t.work.size(),
        [&](std::size_t w) {
          glm::dvec3 sum(0.0);
          for (std::size_t r = 0; r < ns; ++r) {
            const std::uint32_t land = k.land[w * ns + r];
            if (land < kBack) sum += glm::dvec3(reflected[land]);
          }
          next[t.work[w]] = glm::vec3(sum / static_cast<double>(ns));
        },
        256);
    double added = 0.0, total = 0.0;
    for (std::uint32_t i : t.work) {
      added += static_cast<double>(max_abs(next[i] - e[i]));
      total += static_cast<double>(max_abs(next[i]));
    }
    std::swap(e, next);
    iterations = it + 1;
    if (!(added > 1e-4 * total)) break;
  }
  return iterations;
}

// The fresh rays of one texel in step 3: the cosine rays' and the emitter rays' estimate of
// the irradiance that `reflected` sends (W/m^2), and the cosine rays' mean sky radiance; the
// sample variance of one ray's estimate of the luminance of irradiance + pi sky (the mean's
// variance is it over the rays).
struct FreshGather {
  glm::dvec3 irradiance{0.0}, sky{0.0};
  double ray_variance = 0.0;
};

// The variance bookkeeping of gather_texel: each of the n rays estimates the luminance of
// irradiance + pi sky by itself as z (its share of the mean times n).
struct RaySpread {
  double sum = 0.0, squares = 0.0;
  void add(double z) { sum += z, squares += z * z; }
  double variance(double n) const { return n > 1.0 ? std::max(0.0, (squares - sum * sum / n) / (n - 1.0)) : 0.0; }
};

double luminance_of(const glm::dvec3& c) { return luminance(c.x, c.y, c.z); }

// The fresh rays of texel i. Without emitters: the mean of `gather_rays` cosine rays. With
// them: every ray, cosine or emitter-sampled, reading B at a surface point y brings
// B cos_x / pi / (n_c p_c + n_e p_e), p_c = cos_x / pi and p_e the emitter sampling's
// density at y in solid angle (area density x d^2 / cos_y): the balance heuristic, unbiased
// wherever either technique reaches (docs/light_atlas.md, "Emitter-sampled final gather").
// Long because both kinds of rays share the MIS counts and one spread of their estimates
// (the variance); split, the two loops would pass all of them back and forth.
// `pass` > 0: an adaptive pass's rays (another seed; pass 0 is the one every texel gathers).
FreshGather gather_texel(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t,
                         const TexelGatherSettings& s, const GatherSource& src, const TexelEmitters* emitters,
                         std::uint32_t i, std::uint64_t pass, std::uint64_t& rays) {
  const std::uint64_t seed = s.seed ^ (pass * 0x9E3779B97F4A7C15ull);
  const AtlasTexels& tx = b.texels;
  const auto nf = static_cast<std::size_t>(s.gather_rays);
  const auto ne = emitters ? static_cast<std::size_t>(s.emitter_rays) : std::size_t{0};
  const glm::vec3 n = tx.normal[i], origin = offset_ray_origin(tx.position[i], t.face[i]);
  const std::uint32_t group = emitters ? emitters->group_of(i) : 0;
  const double nc = static_cast<double>(nf), n_all = nc + static_cast<double>(ne);
  RaySpread spread;
  // n_e p_e pi / cos_x at a landing: what the emitter rays add to the cosine rays' n_c.
  const auto emitter_count = [&](const Landing& l, float cos_x) {
    if (l.pixel == kDark || !(l.cos_surface > 0.0f)) return 0.0;
    const double d = static_cast<double>(l.distance);
    const double pe =
        static_cast<double>(emitters->area_pdf(group, l.pixel)) * d * d / static_cast<double>(l.cos_surface);
    return static_cast<double>(ne) * pe * static_cast<double>(kPi) / static_cast<double>(cos_x);
  };
  FreshGather g;
  if (nf > 0) {
    Pcg32 rng = Pcg32::for_item(seed, stream_id(i, kGatherStream));
    const float shift_y = rng.next_float();  // drawn first: see random.h
    const glm::vec2 shift(rng.next_float(), shift_y);
    // Cast kRayBatch at a time (land_rays), read in the rays' order (the rng's).
    std::array<Ray, kRayBatch> batch;
    std::array<Landing, kRayBatch> landed;
    for (std::size_t first = 0; first < nf; first += kRayBatch) {
      std::size_t m = 0;
      for (std::size_t r = first; r < std::min(nf, first + kRayBatch); ++r) {
        const glm::vec2 u = hammersley(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(nf), shift);
        const glm::vec3 wi = sample_cosine_hemisphere(n, u.x, u.y);
        if (glm::dot(wi, t.face[i]) > 0.0f) batch[m++] = Ray{origin, 0.0f, wi};
      }
      land_rays(b, lt, t, std::span(batch).first(m), t.face[i], std::span(landed).first(m));
      if (ne > 0)
        for (std::size_t j = 0; j < m; ++j) emitters->prefetch_area_pdf(landed[j].pixel);
      for (std::size_t j = 0; j < m; ++j) {
        const glm::vec3 wi = batch[j].direction;
        const Landing& l = landed[j];
        ++rays;
        double z = 0.0;
        if (l.texel < kBack) {
          const glm::dvec3 radiosity = read_landing(b, t, src, l, rng, rays);
          const glm::dvec3 share = ne == 0 ? radiosity : radiosity / (nc + emitter_count(l, glm::dot(n, wi)));
          g.irradiance += share;
          z = (ne == 0 ? 1.0 : n_all) * luminance_of(share);
        }
        if (l.texel == kSky) {
          g.sky += glm::dvec3(sky_along(b, wi));
          z = n_all / nc * static_cast<double>(kPi) * static_cast<double>(luminance(sky_along(b, wi)));
        }
        spread.add(z);
      }
    }
    g.sky /= nc;
    if (ne == 0) g.irradiance /= nc;
  }
  g.ray_variance = spread.variance(n_all);
  if (ne == 0) return g;
  Pcg32 rng = Pcg32::for_item(seed, stream_id(i, kEmitterStream));
  const float shift_y = rng.next_float();  // drawn first: see random.h
  const glm::vec2 shift(rng.next_float(), shift_y);
  // The members drawn ahead, kPicked rays at a time (their u does not depend on the rays),
  // so that their cache misses overlap instead of stalling each emitter ray in turn.
  constexpr std::size_t kPicked = 64;
  std::array<std::uint32_t, kPicked> picked{};
  for (std::size_t r = 0; r < ne; ++r) {
    const glm::vec2 u = hammersley(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(ne), shift);
    if (r % kPicked == 0)
      for (std::size_t q = r; q < std::min(ne, r + kPicked); ++q)
        picked[q - r] =
            emitters->pick(group, hammersley(static_cast<std::uint32_t>(q), static_cast<std::uint32_t>(ne), shift).x);
    const TexelEmitters::Sample e = emitters->place(picked[r % kPicked], u.y, rng.next_float());
    if (e.texel == TexelEmitters::Sample::kNone) continue;
    const glm::vec3 to = e.point - origin;
    const float d = glm::length(to);
    if (!(d > 0.0f)) continue;
    const glm::vec3 wi = to / d;
    const float cos_x = glm::dot(n, wi);
    if (cos_x <= 0.0f || glm::dot(wi, t.face[i]) <= 0.0f) continue;
    ++rays;
    const Landing l = land_ray(b, lt, t, Ray{origin, 0.0f, wi}, t.face[i]);
    if (l.texel >= kBack || l.pixel != e.texel) continue;  // occluded, or off the surface
    // B cos_x / pi / (n_c p_c + n_e p_e) = B / (n_c + n_e p_e pi / cos_x).
    const double count = nc + emitter_count(l, cos_x);
    if (!(count > 0.0)) continue;
    const glm::dvec3 share = read_landing(b, t, src, l, rng, rays) / count;  // as the cosine rays read
    g.irradiance += share;
    spread.add(n_all * luminance_of(share));
  }
  g.ray_variance = spread.variance(n_all);
  return g;
}

// Step 3 for the texels `mine` (work items): `gather_rays` fresh stratified rays (and
// `emitter_rays` towards `emitters`) read `reflected` (rho (E_d + E), dilated) bilinearly
// where they land, and the sky where they escape. Each estimate is averaged with step 2's
// (in e and k.sky), weighted by ray counts. Texels not in `mine` get 0 in both.
bool final_gather(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const TexelGatherSettings& s,
                  ThreadPool& pool, const ProgressCallback& progress, const std::vector<std::size_t>& mine,
                  const GatherSource& src, const TexelEmitters* emitters, const KeptRays& k,
                  const std::vector<std::uint8_t>& extra, std::vector<glm::vec3>& e, std::vector<glm::vec3>& sky,
                  std::vector<float>& variance, std::vector<std::uint64_t>& rays_of) {
  const auto nf = static_cast<std::size_t>(s.gather_rays);
  const auto ne = emitters ? static_cast<std::size_t>(s.emitter_rays) : std::size_t{0};
  std::vector<glm::vec3> gathered(e.size(), glm::vec3(0.0f));
  sky.assign(e.size(), glm::vec3(0.0f));
  const bool done = pool.parallel_for_with_progress(mine.size(), progress, [&](std::size_t m) {
    const std::size_t w = mine[m];
    const std::uint32_t i = t.work[w];
    // The texel's passes (1, or 1 + adaptive_passes where `extra` chose it): their mean.
    const std::uint64_t passes = 1 + (extra.empty() || !extra[w] ? 0 : static_cast<std::uint64_t>(s.adaptive_passes));
    FreshGather g;
    for (std::uint64_t p = 0; p < passes; ++p) {
      const FreshGather one = gather_texel(b, lt, t, s, src, emitters, i, p, rays_of[w]);
      g.irradiance += one.irradiance, g.sky += one.sky, g.ray_variance += one.ray_variance;
    }
    const double per_pass = 1.0 / static_cast<double>(passes), fresh = static_cast<double>(passes * nf);
    // Both estimate T(E_d + E): weighted by their rays (the sky by the cosine rays alone).
    // With emitter rays the kept rays are left out: read at their landing texels without MIS
    // weights (their hit points are not kept), they would bring back the cosine rays' noise
    // (on the skylit room: 95th-percentile texel 0.36 with them, 0.23 without).
    const double kept = static_cast<double>(k.per_texel);
    const double w_solve = ne > 0 ? 0.0 : kept / (kept + fresh);
    const double w_sky = kept / (kept + fresh);
    gathered[i] = glm::vec3(w_solve * glm::dvec3(e[i]) + (1.0 - w_solve) * per_pass * g.irradiance);
    sky[i] = glm::vec3(w_sky * glm::dvec3(k.sky[i]) + (1.0 - w_sky) * static_cast<double>(kPi) * per_pass * g.sky);
    // The mean's variance: the kept rays spread as the cosine rays do, so with them it is the
    // fresh rays' spread over all the rays.
    const double rays = fresh + static_cast<double>(passes * ne) + (w_solve > 0.0 ? kept : 0.0);
    variance[i] = static_cast<float>(per_pass * g.ray_variance / rays);
  });
  e = std::move(gathered);
  return done;
}

// Step 3's adaptive choice (TexelGatherSettings::adaptive_share): per work item, 1 for the
// share of the texels whose kept rays read the most variable light in `reflected` (the sample
// variance of the luminance each ray brings, the sky's rays at their mean), else 0. The kept
// rays are independent of step 3's, so the choice does not bias the gathers it adds to.
std::vector<std::uint8_t> adaptive_choice(const TexelTable& t, const KeptRays& k,
                                          const std::vector<glm::vec3>& reflected, float share, ThreadPool& pool) {
  const std::size_t work = t.work.size(), ns = k.per_texel;
  if (!(share > 0.0f) || work == 0 || ns < 2) return {};
  std::vector<double> spread(work, 0.0);
  pool.parallel_for(
      work,
      [&](std::size_t w) {
        const std::uint32_t i = t.work[w];
        std::size_t sky_rays = 0;
        for (std::size_t r = 0; r < ns; ++r) sky_rays += k.land[w * ns + r] == kSky;
        const double sky = sky_rays ? luminance(k.sky[i].x, k.sky[i].y, k.sky[i].z) * static_cast<double>(ns) /
                                          static_cast<double>(sky_rays)
                                    : 0.0;
        double sum = 0.0, squares = 0.0;
        for (std::size_t r = 0; r < ns; ++r) {
          const std::uint32_t land = k.land[w * ns + r];
          const glm::vec3& c = land < kBack ? reflected[land] : glm::vec3(0.0f);
          const double z = land == kSky ? sky : land < kBack ? luminance(c.x, c.y, c.z) : 0.0;
          sum += z, squares += z * z;
        }
        const double n = static_cast<double>(ns);
        spread[w] = std::max(0.0, (squares - sum * sum / n) / (n - 1.0));
      },
      256);
  std::vector<double> sorted = spread;
  const auto keep = static_cast<std::size_t>(std::ceil(static_cast<double>(share) * static_cast<double>(work)));
  std::vector<std::uint8_t> chosen(work, 0);
  if (keep == 0) return chosen;
  const std::size_t at = work - std::min(keep, work);
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(at), sorted.end());
  const double threshold = sorted[at];
  for (std::size_t w = 0; w < work; ++w) chosen[w] = spread[w] >= threshold && spread[w] > 0.0 ? 1 : 0;
  return chosen;
}

// Step 3: the final gather reads the kept-ray solve's light (filtered as the settings ask:
// its noise would otherwise come back as blotches a few texels wide, a bright texel lighting
// its neighbours' rays). `out.indirect` holds the solve on entry and the gather on return;
// `sky` the sky's direct light, likewise.
bool gather_step(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t, LandingTable& lt,
                 const TexelGatherSettings& s, ThreadPool& pool, const ProgressCallback& progress, const KeptRays& kept,
                 const std::vector<glm::vec3>& emitted, const std::vector<glm::vec3>& sampled, TexelGatherResult& out,
                 std::vector<glm::vec3>& sky) {
  const AtlasTexels& tx = b.texels;
  const std::size_t n = tx.valid.size(), work = t.work.size();
  const float texel_m = layout.texels_per_metre > 0.0f ? 1.0f / layout.texels_per_metre : 0.0f;
  const float source_radius =
      s.source_filter_radius_texels < 0.0f ? s.filter_radius_texels : s.source_filter_radius_texels;
  const bool filtering = source_radius > 0.0f && texel_m > 0.0f;
  const float radius_m = source_radius * texel_m;
  std::vector<glm::vec3>& e = out.indirect;
  const std::vector<glm::vec3> source =
      filtering ? filter_world(tx, t.work, e, kept.hidden, radius_m, texel_m, pool, s.source_filter_slope_ridge) : e;
  GatherSource src;
  src.reflected.assign(n, glm::vec3(0.0f));
  src.without_lights.assign(n, glm::vec3(0.0f));
  std::vector<glm::vec3> lit(n, glm::vec3(0.0f));
  for (std::uint32_t i : t.work) {
    src.reflected[i] = t.albedo[i] * (emitted[i] + source[i]);
    src.without_lights[i] = t.albedo[i] * (kept.sky[i] + source[i]);
    lit[i] = t.albedo[i] * (out.direct[i] + out.baked_direct[i]);
  }
  std::optional<TexelEmitters> emitters;
  if (s.emitter_rays > 0) emitters.emplace(b, layout, t.work, t.face, src.reflected, layout.texels_per_metre, pool);
  const int rings = std::max(3, layout.padding_texels);
  for (auto* field : {&src.reflected, &src.without_lights, &lit})
    dilate<glm::vec3>(*field, t.width, t.height, tx.valid, rings);
  src.sharp = s.landing_direct == TexelGatherSettings::LandingDirect::Everywhere ? std::vector<std::uint8_t>(n, 1)
                                                                                 : sharp_pixels(lit, t.width, t.height);
  if (s.landing_direct == TexelGatherSettings::LandingDirect::Punctual) {
    src.punctual_everywhere = true;
    src.without_punctual.assign(n, glm::vec3(0.0f));
    for (std::uint32_t i : t.work) src.without_punctual[i] = t.albedo[i] * (kept.sky[i] + source[i] + sampled[i]);
    dilate<glm::vec3>(src.without_punctual, t.width, t.height, tx.valid, rings);
  }
  mark_sharp(lt, src.sharp);
  src.table = &lt;
  src.near_rays = s.near_regather_rays;
  src.near_m = s.near_regather_texels * texel_m;
  src.near_depth = s.near_regather_depth;
  src.near_deep_rays = s.near_regather_deep_rays;
  std::vector<std::uint64_t> gather_rays_of(work, 0);
  const std::vector<std::uint8_t> extra = adaptive_choice(t, kept, src.reflected, s.adaptive_share, pool);
  if (!final_gather(b, lt, t, s, pool, progress, s.shard.items(work), src, emitters ? &*emitters : nullptr, kept, extra,
                    e, sky, out.variance, gather_rays_of))
    return false;
  for (std::uint64_t r : gather_rays_of) out.own_rays += r;
  return true;
}

// Step 4 on both filtered fields (indirect and the baked direct light): the denoiser, then
// the filter, as the settings ask.
void filter_result(const AtlasTexels& tx, const TexelTable& t, const TexelGatherSettings& s, float texel_m,
                   ThreadPool& pool, TexelGatherResult& out) {
  if (s.denoise_passes > 0 && texel_m > 0.0f) {
    std::vector<glm::vec3>* const fields[] = {&out.indirect, &out.baked_direct};
    denoise_world(tx, t.work, out.hidden, texel_m,
                  {.passes = s.denoise_passes,
                   .value_sigma = s.denoise_sigma,
                   .outlier_sigmas = s.denoise_outlier_sigmas,
                   .slope_ridge = s.denoise_slope_ridge},
                  pool, out.variance, fields);
  }
  if (s.filter_radius_texels <= 0.0f || !(texel_m > 0.0f)) return;
  const float radius_m = s.filter_radius_texels * texel_m;
  out.indirect = filter_world(tx, t.work, out.indirect, out.hidden, radius_m, texel_m, pool);
  out.baked_direct = filter_world(tx, t.work, out.baked_direct, out.hidden, radius_m, texel_m, pool);
}

}  // namespace

// Long because it is texel_gather.h's four steps in order, each a call of its own, timed and
// sharing the texel table, the kept rays and the progress phases; split further, those would
// travel between the steps as parameters without making any step easier to read.
engine::Result<TexelGatherResult> gather_atlas(const StaticBakeScene& b, const AtlasLayout& layout,
                                               const TexelGatherSettings& s, ThreadPool& pool) {
  if (auto ok = validate(s); !ok) return ok.error();
  auto table = texel_table(b, layout);
  if (!table) return table.error();
  const TexelTable& t = *table;
  auto packed = landing_table(b, layout, t);
  if (!packed) return packed.error();
  LandingTable& lt = *packed;
  const AtlasTexels& tx = b.texels;
  const std::size_t n = tx.valid.size(), work = t.work.size();
  const auto phase = [&](double begin, double end) -> ProgressCallback {
    if (!s.progress) return {};
    return [&s, begin, end](double f) { return s.progress(begin + (end - begin) * f); };
  };
  TexelGatherResult out;
  out.direct.assign(n, glm::vec3(0.0f));
  out.baked_direct.assign(n, glm::vec3(0.0f));
  out.indirect.assign(n, glm::vec3(0.0f));
  out.variance.assign(n, 0.0f);
  std::vector<std::uint64_t> rays_of(work, 0);
  std::vector<glm::vec3> sampled(n, glm::vec3(0.0f));  // step 1's area lights and emitters (DirectAt::sampled)

  // Step 1.
  auto t0 = Clock::now();
  if (!pool.parallel_for_with_progress(work, phase(0.0, 0.15), [&](std::size_t w) {
        const std::uint32_t i = t.work[w];
        Pcg32 rng = Pcg32::for_item(s.seed, stream_id(i, kDirectStream));
        const DirectAt d = direct_at(b, tx.position[i], tx.normal[i], t.face[i], s.direct_samples, rng, &rays_of[w]);
        out.direct[i] = d.live;
        out.baked_direct[i] = d.unlit;
        sampled[i] = d.sampled;
      }))
    return engine::cancelled_error("light-atlas gather");
  out.direct_seconds = seconds_since(t0);

  // Step 2. Every texel reflects the direct light of the lights, of the emitters and of the sky.
  t0 = Clock::now();
  KeptRays kept;
  if (!cast_kept_rays(b, lt, t, s, pool, phase(0.15, 0.45), rays_of, kept))
    return engine::cancelled_error("light-atlas gather");
  std::vector<glm::vec3> emitted(n, glm::vec3(0.0f));
  for (std::uint32_t i : t.work) emitted[i] = out.direct[i] + out.baked_direct[i] + kept.sky[i];
  std::vector<glm::vec3>& e = out.indirect;
  out.iterations = solve_kept_rays(t, kept, emitted, s.bounces, pool, e);
  out.solve_seconds = seconds_since(t0);
  if (s.progress && !s.progress(0.5)) return engine::cancelled_error("light-atlas gather");

  // Step 3.
  t0 = Clock::now();
  std::vector<glm::vec3> sky = kept.sky;
  if (s.gather_rays > 0 || s.emitter_rays > 0) {
    if (!gather_step(b, layout, t, lt, s, pool, phase(0.5, 0.95), kept, emitted, sampled, out, sky))
      return engine::cancelled_error("light-atlas gather");
  } else if (!s.shard.whole()) {
    for (std::size_t w = 0; w < work; ++w)
      if (!s.shard.owns(w)) e[t.work[w]] = sky[t.work[w]] = glm::vec3(0.0f);
  }
  for (std::uint32_t i : t.work) out.baked_direct[i] += sky[i];
  out.gather_seconds = seconds_since(t0);
  for (std::uint64_t r : rays_of) out.shared_rays += r;
  out.rays = out.shared_rays + out.own_rays;
  out.hidden = std::move(kept.hidden);

  // Step 4 (a shard leaves it to the merge).
  if (s.part_only) return out;
  t0 = Clock::now();
  const float texel_m = layout.texels_per_metre > 0.0f ? 1.0f / layout.texels_per_metre : 0.0f;
  filter_result(tx, t, s, texel_m, pool, out);
  out.filter_seconds = seconds_since(t0);
  if (s.progress && !s.progress(1.0)) return engine::cancelled_error("light-atlas gather");
  return out;
}

engine::Result<std::vector<glm::vec3>> sky_direct_light(const StaticBakeScene& b, const AtlasLayout& layout, int rays,
                                                        std::uint64_t seed, ThreadPool& pool) {
  if (rays < 1) return engine::invalid_request("the sky's direct light: rays must be >= 1");
  auto table = texel_table(b, layout);
  if (!table) return table.error();
  auto packed = landing_table(b, layout, *table);
  if (!packed) return packed.error();
  std::vector<std::uint64_t> rays_of(table->work.size(), 0);
  TexelGatherSettings s;
  s.solve_rays = rays;
  s.seed = seed;
  KeptRays kept;
  cast_kept_rays(b, *packed, *table, s, pool, {}, rays_of, kept);
  return std::move(kept.sky);
}

// The same filter call as gather_atlas's step 4, for a result merged from shards.
engine::Status filter_gathered(const StaticBakeScene& b, const AtlasLayout& layout, const TexelGatherSettings& s,
                               ThreadPool& pool, TexelGatherResult& out) {
  const auto t0 = Clock::now();
  const float texel_m = layout.texels_per_metre > 0.0f ? 1.0f / layout.texels_per_metre : 0.0f;
  if ((s.filter_radius_texels > 0.0f || s.denoise_passes > 0) && texel_m > 0.0f) {
    auto table = texel_table(b, layout);
    if (!table) return table.error();
    const std::size_t n = b.texels.valid.size();
    if (out.indirect.size() != n || out.baked_direct.size() != n || out.hidden.size() != n ||
        (s.denoise_passes > 0 && out.variance.size() != n))
      return engine::Error{.message = "texel gather: the result to filter does not match the atlas"};
    filter_result(b.texels, *table, s, texel_m, pool, out);
  }
  out.filter_seconds = seconds_since(t0);
  return {};
}

std::vector<glm::vec3> irradiance_at_points(const AtlasTexels& texels, const std::vector<glm::vec3>& irradiance,
                                            float texels_per_metre, std::span<const glm::vec3> points,
                                            std::span<const glm::vec3> normals) {
  std::vector<std::uint32_t> valid;
  for (std::size_t i = 0; i < texels.valid.size(); ++i)
    if (texels.valid[i]) valid.push_back(static_cast<std::uint32_t>(i));
  const float reach = 2.0f / texels_per_metre;
  const TexelCells cells(texels, valid, reach);
  std::vector<glm::vec3> out(points.size(), glm::vec3(0.0f));
  for (std::size_t k = 0; k < points.size(); ++k) {
    float best = reach * reach;
    std::uint32_t found = kDark;
    cells.for_around(cells.cell_of(points[k]), [&](std::uint32_t j) {
      const glm::vec3 d = texels.position[j] - points[k];
      const float d2 = glm::dot(d, d);
      if (d2 < best && glm::dot(texels.normal[j], normals[k]) > 0.5f) best = d2, found = j;
    });
    if (found != kDark) out[k] = irradiance[found];
  }
  return out;
}

}  // namespace gi
