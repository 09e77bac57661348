#include "light_atlas/texel_gather.h"

#include <engine/gltf_brdf.h>
#include <engine/sky.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <unordered_map>

#include "core/color.h"
#include "core/random.h"
#include "core/stopwatch.h"
#include "light_atlas/atlas_denoise.h"
#include "light_atlas/texel_cells.h"
#include "light_atlas/texel_direct.h"
#include "light_atlas/texel_emitters.h"
#include "light_atlas/texel_filter.h"
#include "light_atlas/texel_sampling.h"
#include "raytrace/material_lookup.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"
#include "uv/atlas_dilation.h"

namespace gi {
namespace {

using Clock = std::chrono::steady_clock;

constexpr float kPi = std::numbers::pi_v<float>;
constexpr std::uint32_t kDark = 0xffffffffu;  // a ray into the surface, or nothing to read
constexpr std::uint32_t kSky = 0xfffffffeu;   // the ray escaped
constexpr std::uint32_t kBack = 0xfffffffdu;  // the back of a one-sided surface (black)
// A texel whose kept rays see back faces this often lies inside or under geometry; the
// filter neither reads nor smooths it.
constexpr float kHiddenBackFraction = 0.1f;
// Two surfaces facing each other closer than this (in texels) enclose a gap no light enters
// (a slab's underside 2 mm above the next one's top, in Dabrovic Sponza): a ray from one
// that lands on the other reads dark, not the texel there, whose sample lies in the open.
constexpr float kGapTexels = 0.05f;
// A texel's sample this far off its triangle's plane was moved by relocate_texel_samples (at
// least 0.01 texel off its surface): whether it sees a point where a ray lands on its texel
// is checked (Landing::unseen_corners).
constexpr float kOffPlaneTexels = 0.001f;

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
  return {};
}

// What the gather knows of every texel of the atlas.
struct TexelTable {
  int width = 0, height = 0;
  std::vector<std::uint32_t> work;      // valid texels in index order
  std::vector<glm::vec3> albedo;        // per atlas texel: hemispherical albedo of its material
  std::vector<glm::vec3> face;          // per atlas texel: unit geometric normal on the shading side
  std::vector<std::uint32_t> redirect;  // per atlas texel: itself when valid, else a valid neighbour or kDark
  float gap_m = 0.0f;                   // kGapTexels in metres
  float plane_m = 0.0f;                 // kOffPlaneTexels in metres
  std::vector<std::uint8_t> moved;      // per atlas texel: its sample lies off its triangle's plane
  float near_m = 0.0f;                  // one texel in metres
};

// TexelTable::moved: the samples relocate_texel_samples moved off their triangle's plane.
void mark_moved_samples(const StaticBakeScene& b, TexelTable& t) {
  const AtlasTexels& tx = b.texels;
  t.moved.assign(tx.valid.size(), 0);
  for (std::uint32_t i : t.work) {
    const std::uint32_t mesh = static_cast<std::uint32_t>(tx.mesh[i]);
    const ShadingTriangle& tri =
        b.index.triangles[b.index.instance_first[b.static_instance[mesh]] + static_cast<std::uint32_t>(tx.triangle[i])];
    t.moved[i] = std::fabs(glm::dot(tx.position[i] - tri.p0, tri.face_normal)) > t.plane_m ? 1 : 0;
  }
}

engine::Result<TexelTable> texel_table(const StaticBakeScene& b, const AtlasLayout& layout) {
  // Long because it fills one table in one pass over the texels: the layout checks, the
  // per-texel albedo and face, then the gutter redirects that read what that pass wrote.
  const AtlasTexels& tx = b.texels;
  if (tx.width != layout.width || tx.height != layout.height || layout.meshes.size() != b.static_instance.size())
    return engine::Error{.message = "texel gather: the atlas layout does not match the bake scene"};
  for (std::size_t m = 0; m < layout.meshes.size(); ++m) {
    const auto [first, end] = instance_triangles(b.index, b.static_instance[m]);
    if (layout.meshes[m].indices.size() != 3u * (end - first))
      return engine::Error{.message = "texel gather: atlas mesh " + std::to_string(m) +
                                      " has another triangle count than its static instance"};
  }
  TexelTable t;
  t.width = tx.width;
  t.height = tx.height;
  t.gap_m = layout.texels_per_metre > 0.0f ? kGapTexels / layout.texels_per_metre : 0.0f;
  t.plane_m = layout.texels_per_metre > 0.0f ? kOffPlaneTexels / layout.texels_per_metre : 0.0f;
  t.near_m = layout.texels_per_metre > 0.0f ? 1.0f / layout.texels_per_metre : 0.0f;
  const std::size_t n = tx.valid.size();
  t.albedo.assign(n, glm::vec3(0.0f));
  t.face.assign(n, glm::vec3(0.0f));
  t.redirect.assign(n, kDark);
  std::unordered_map<std::uint32_t, glm::vec3> albedo_of;
  for (std::size_t i = 0; i < n; ++i) {
    if (!tx.valid[i]) continue;
    t.work.push_back(static_cast<std::uint32_t>(i));
    t.redirect[i] = static_cast<std::uint32_t>(i);
    const std::uint32_t mesh = static_cast<std::uint32_t>(tx.mesh[i]);
    const ShadingTriangle& tri =
        b.index.triangles[b.index.instance_first[b.static_instance[mesh]] + static_cast<std::uint32_t>(tx.triangle[i])];
    if (b.scene.materials[tri.material].textured()) {
      // The texture's mean over the texel's footprint (material_lookup.h), not one point.
      const TexelFootprint f = texel_footprint(layout, tx.mesh[i], tx.triangle[i], i);
      t.albedo[i] = footprint_albedo(b.scene, tri, f.centre, f.axis_u, f.axis_v);
      t.face[i] = glm::dot(tri.face_normal, tx.normal[i]) < 0.0f ? -tri.face_normal : tri.face_normal;
      continue;
    }
    auto it = albedo_of.find(tri.material);
    if (it == albedo_of.end())
      it =
          albedo_of.emplace(tri.material, engine::gltf_hemispherical_albedo(b.scene.materials[tri.material].brdf).sum())
              .first;
    t.albedo[i] = it->second;
    t.face[i] = glm::dot(tri.face_normal, tx.normal[i]) < 0.0f ? -tri.face_normal : tri.face_normal;
  }
  // Rays landing on an empty texel of a chart (its gutter, a sliver's corner) read the
  // nearest valid one, found ring by ring in a fixed neighbour order.
  for (int ring = 0; ring < std::max(3, layout.padding_texels); ++ring) {
    std::vector<std::pair<std::size_t, std::uint32_t>> found;
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x) {
        const std::size_t i = tx.index(x, y);
        if (t.redirect[i] != kDark) continue;
        for (int k = 0; k < 9; ++k) {
          const int nx = x + k % 3 - 1, ny = y + k / 3 - 1;
          if (nx < 0 || ny < 0 || nx >= t.width || ny >= t.height) continue;
          const std::uint32_t r = t.redirect[tx.index(nx, ny)];
          if (r == kDark) continue;
          found.emplace_back(i, r);
          break;
        }
      }
    if (found.empty()) break;
    for (const auto& [i, r] : found) t.redirect[i] = r;
  }
  mark_moved_samples(b, t);
  return t;
}

glm::vec2 hit_uv(const AtlasLayout& layout, const Hit& h) {
  const AtlasMeshUv& mu = layout.meshes[h.instance];
  const std::uint32_t* idx = &mu.indices[3u * h.primitive];
  const float u = h.barycentric.x, v = h.barycentric.y;
  return (1.0f - u - v) * mu.uv1[idx[0]] + u * mu.uv1[idx[1]] + v * mu.uv1[idx[2]];
}

// Where a ray from a texel whose face is `from` ends: kSky, kBack (the back of a one-sided
// surface, or a surface facing `from` across a gap of less than kGapTexels) or the atlas texel
// it reads (a valid texel, redirected from an empty one); on a surface also the atlas UV of the
// hit, the atlas texel under it as it is (`pixel`, maybe empty), the distance and |cos| at the
// surface, and the hit itself (its triangle, barycentrics, the side the ray came from).
struct Landing {
  std::uint32_t texel = kSky;
  glm::vec2 uv{0.0f};
  std::uint32_t pixel = kDark;
  float distance = 0.0f, cos_surface = 0.0f;
  std::uint32_t triangle = 0;
  glm::vec2 barycentric{0.0f};
  glm::vec3 side{0.0f};  // the hit triangle's unit face normal turned towards the ray's origin
  // Bit k: the sample of the bilinear read's corner k does not see the landing point (its
  // light is not the point's).
  std::uint8_t unseen_corners = 0;
};

// The four atlas pixels of a bilinear read at uv (bilinear()'s), corner k = (x0 + k % 2, y0 + k / 2),
// and its fractions.
struct Footprint {
  std::size_t pixel[4];
  float ax, ay;
};

Footprint footprint_at(int w, int h, glm::vec2 uv) {
  const float fx = uv.x * static_cast<float>(w) - 0.5f, fy = uv.y * static_cast<float>(h) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  Footprint f{};
  f.ax = fx - x0f, f.ay = fy - y0f;
  for (int k = 0; k < 4; ++k) {
    const int x = std::clamp(static_cast<int>(x0f) + k % 2, 0, w - 1),
              y = std::clamp(static_cast<int>(y0f) + k / 2, 0, h - 1);
    f.pixel[k] = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
  }
  return f;
}

// Whether the sample of `texel` does not see the point p on a surface facing `side` where a
// ray landed on that texel. Sponza's stacked slabs enclose pockets a few centimetres tall,
// closed on every side (the path tracer finds no light at all in them), whose floor's texels
// have their samples moved through the pocket's walls into the sun by relocate_texel_samples:
// a ray landing inside the pocket read 760 W/m^2 there.
bool sample_unseen(const StaticBakeScene& b, const TexelTable& t, const glm::vec3& p, const glm::vec3& side,
                   std::uint32_t texel) {
  const glm::vec3 q = b.texels.position[texel];
  const glm::vec3 from = offset_ray_origin(p, side), to = offset_ray_origin(q, t.face[texel]);
  return b.caster->occluded(Ray{from, 0.0f, to - from, 1.0f});
}

// A ray from a texel landed on a surface facing it closer than kGapTexels: the two enclose a
// dark gap only if something covers the landing point. A texel's sample moved off its
// triangle by relocate_texel_samples (raytrace/texel_samples.h) can float that close over a
// surface in the open (Dabrovic Sponza's gallery floor 0.8 mm under such a sample sees the
// sun). One ray from the landing point back out along its side, as long as the gap, decides.
bool gap_is_covered(const StaticBakeScene& b, const TexelTable& t, const Ray& ray, const Hit& h,
                    const glm::vec3& side) {
  const glm::vec3 p = ray.origin + h.t * ray.direction;
  return b.caster->occluded(Ray{offset_ray_origin(p, side), 0.0f, side, 2.0f * t.gap_m});
}

// Landing::unseen_corners at the landing point p, `distance` from the ray's
// origin: each sample checked once, the moved ones always, all of them on a landing closer
// than a texel (a pocket's floor whose texels' samples lie beyond its walls).
void mark_unseen(const StaticBakeScene& b, const TexelTable& t, const glm::vec3& p, float distance, Landing& l) {
  const Footprint f = footprint_at(t.width, t.height, l.uv);
  const bool near = distance < t.near_m;
  std::uint32_t checked[5] = {l.texel, kDark, kDark, kDark, kDark};
  bool unseen[5] = {(near || t.moved[l.texel] != 0) && sample_unseen(b, t, p, l.side, l.texel)};
  for (int k = 0; k < 4; ++k) {
    const std::uint32_t j = t.redirect[f.pixel[k]];
    if (j == kDark || !(near || t.moved[j])) continue;
    int c = 0;
    while (c <= k && checked[c] != j && checked[c] != kDark) ++c;
    if (checked[c] != j) checked[c] = j, unseen[c] = sample_unseen(b, t, p, l.side, j);
    if (unseen[c]) l.unseen_corners = static_cast<std::uint8_t>(l.unseen_corners | (1u << k));
  }
}

Landing land_ray(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t, const Ray& ray,
                 const glm::vec3& from) {
  const Hit h = b.caster->intersect(ray);
  if (!h.valid()) return {};
  const ShadingTriangle& tri = b.index.triangles[b.triangle_of(h)];
  const float cos_surface = glm::dot(tri.face_normal, ray.direction);
  if (!(cos_surface < 0.0f) && !b.scene.materials[tri.material].double_sided) return {.texel = kBack};
  const glm::vec3 side = cos_surface < 0.0f ? tri.face_normal : -tri.face_normal;
  if (h.t < t.gap_m && std::fabs(glm::dot(tri.face_normal, from)) > 0.9f && gap_is_covered(b, t, ray, h, side))
    return {.texel = kBack};
  Landing l;
  l.triangle = b.triangle_of(h);
  l.barycentric = h.barycentric;
  l.side = side;
  l.uv = hit_uv(layout, h);
  const int x = std::clamp(static_cast<int>(l.uv.x * static_cast<float>(t.width)), 0, t.width - 1);
  const int y = std::clamp(static_cast<int>(l.uv.y * static_cast<float>(t.height)), 0, t.height - 1);
  l.pixel = static_cast<std::uint32_t>(static_cast<std::size_t>(y) * static_cast<std::size_t>(t.width) +
                                       static_cast<std::size_t>(x));
  l.texel = t.redirect[l.pixel];
  if (l.texel != kDark) mark_unseen(b, t, ray.origin + h.t * ray.direction, h.t, l);
  l.distance = h.t;
  l.cos_surface = std::fabs(cos_surface);
  return l;
}

std::uint32_t landing(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t, const Ray& ray,
                      const glm::vec3& from, glm::vec2* uv) {
  const Landing l = land_ray(b, layout, t, ray, from);
  if (uv && l.texel != kSky && l.texel != kBack) *uv = l.uv;
  return l.texel;
}

glm::vec3 bilinear(const std::vector<glm::vec3>& img, int w, int h, glm::vec2 uv) {
  const float fx = uv.x * static_cast<float>(w) - 0.5f, fy = uv.y * static_cast<float>(h) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  const int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
  const auto at = [&](int x, int y) {
    x = std::clamp(x, 0, w - 1);
    y = std::clamp(y, 0, h - 1);
    return img[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
  };
  return (1.0f - ay) * ((1.0f - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1.0f - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

float max_abs(const glm::vec3& v) { return std::max(std::fabs(v.x), std::max(std::fabs(v.y), std::fabs(v.z))); }

}  // namespace

namespace {

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
bool cast_kept_rays(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t,
                    const TexelGatherSettings& s, ThreadPool& pool, const ProgressCallback& progress,
                    std::vector<std::uint64_t>& rays_of, KeptRays& k) {
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
    for (std::size_t r = 0; r < ns; ++r) {
      const glm::vec2 u = hammersley(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(ns), shift);
      const glm::vec3 wi = sample_cosine_hemisphere(tx.normal[i], u.x, u.y);
      if (glm::dot(wi, t.face[i]) <= 0.0f) continue;  // below the surface: dark
      ++rays_of[w];
      const std::uint32_t land = landing(b, layout, t, Ray{origin, 0.0f, wi}, t.face[i], nullptr);
      k.land[w * ns + r] = land;
      if (land == kSky) sky_seen += sky_along(b, wi);
      back += land == kBack;
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

// What step 3's rays read, per atlas pixel (dilated): rho (E_d + E) of every texel, the same
// without the lights' direct light, rho (sky + E), and where the lights' direct light changes
// sharply (`sharp`: in the pixel's 3 x 3 neighbourhood the dimmest is under half the
// brightest, a shadow edge crossing it).
struct GatherSource {
  std::vector<glm::vec3> reflected, without_lights;
  std::vector<std::uint8_t> sharp;
};

// A texel holds the light at its one sample point. Where a shadow edge crosses it, the light
// of another point of the texel can be anything between its neighbours': in a 5 cm slot
// under a slab of Dabrovic Sponza, the floor's texel straddles the slot's mouth, its sample
// lies in the sun, and rays from the slab's underside that land in the dark slot read that
// sun (issue 35, "Noise against floor"). There the read takes the lights' direct light at the
// landing point itself (one sample of each light, unbiased) and only the rest bilinearly.
// Bilinear corners whose samples do not see the point (Landing::unseen_corners) are left out;
// where none does, that direct light is all the read takes.
glm::dvec3 read_landing(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l,
                        Pcg32& rng, std::uint64_t& rays) {
  const bool sharp = src.sharp[l.pixel] != 0;
  if (l.unseen_corners == 0 && !sharp) return glm::dvec3(bilinear(src.reflected, t.width, t.height, l.uv));
  glm::dvec3 rest(0.0);
  if (l.unseen_corners != 0) {
    // The bilinear read without the corners whose samples do not see the point.
    const Footprint f = footprint_at(t.width, t.height, l.uv);
    const std::vector<glm::vec3>& img = sharp ? src.without_lights : src.reflected;
    double weights = 0.0;
    for (int k = 0; k < 4; ++k) {
      if (l.unseen_corners & (1u << k)) continue;
      const double wk = static_cast<double>((k % 2 ? f.ax : 1.0f - f.ax) * (k / 2 ? f.ay : 1.0f - f.ay));
      rest += wk * glm::dvec3(img[f.pixel[k]]), weights += wk;
    }
    if (weights > 0.0) rest /= weights;
    if (!sharp && weights > 0.0) return rest;
    if (!(weights > 0.0)) rest = glm::dvec3(0.0);
  } else {
    rest = glm::dvec3(bilinear(src.without_lights, t.width, t.height, l.uv));
  }
  const ShadingTriangle& tri = b.index.triangles[l.triangle];
  const float u = l.barycentric.x, v = l.barycentric.y;
  const glm::vec3 p = tri.p0 + u * tri.e1 + v * tri.e2;
  glm::vec3 n = (1.0f - u - v) * tri.n0 + u * tri.n1 + v * tri.n2;
  n = glm::dot(n, n) > 0.0f ? glm::normalize(n) : l.side;
  if (glm::dot(n, l.side) < 0.0f) n = -n;  // a double-sided surface seen from behind
  const DirectAt d = direct_at(b, p, n, l.side, 1, rng, &rays);
  const glm::dvec3 lights(t.albedo[l.texel] * (d.live + d.unlit));
  return rest + lights;
}

// Marks the pixels whose 3 x 3 neighbourhood of `lit` (rho E_d, dilated) holds a sharp change.
std::vector<std::uint8_t> sharp_pixels(const std::vector<glm::vec3>& lit, int w, int h) {
  std::vector<std::uint8_t> sharp(lit.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
      for (int k = 0; k < 9; ++k) {
        const int nx = std::clamp(x + k % 3 - 1, 0, w - 1), ny = std::clamp(y + k / 3 - 1, 0, h - 1);
        const glm::vec3& c =
            lit[static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) + static_cast<std::size_t>(nx)];
        const float l = luminance(c.x, c.y, c.z);
        lo = std::min(lo, l), hi = std::max(hi, l);
      }
      sharp[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
          hi > 0.0f && lo < 0.5f * hi ? 1 : 0;
    }
  return sharp;
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
FreshGather gather_texel(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t,
                         const TexelGatherSettings& s, const GatherSource& src, const TexelEmitters* emitters,
                         std::uint32_t i, std::uint64_t& rays) {
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
    Pcg32 rng = Pcg32::for_item(s.seed, stream_id(i, kGatherStream));
    const float shift_y = rng.next_float();  // drawn first: see random.h
    const glm::vec2 shift(rng.next_float(), shift_y);
    for (std::size_t r = 0; r < nf; ++r) {
      const glm::vec2 u = hammersley(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(nf), shift);
      const glm::vec3 wi = sample_cosine_hemisphere(n, u.x, u.y);
      if (glm::dot(wi, t.face[i]) <= 0.0f) continue;
      ++rays;
      const Landing l = land_ray(b, layout, t, Ray{origin, 0.0f, wi}, t.face[i]);
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
    g.sky /= nc;
    if (ne == 0) g.irradiance /= nc;
  }
  g.ray_variance = spread.variance(n_all);
  if (ne == 0) return g;
  Pcg32 rng = Pcg32::for_item(s.seed, stream_id(i, kEmitterStream));
  const float shift_y = rng.next_float();  // drawn first: see random.h
  const glm::vec2 shift(rng.next_float(), shift_y);
  for (std::size_t r = 0; r < ne; ++r) {
    const glm::vec2 u = hammersley(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(ne), shift);
    const TexelEmitters::Sample e = emitters->sample(group, u.x, u.y, rng.next_float());
    if (e.texel == TexelEmitters::Sample::kNone) continue;
    const glm::vec3 to = e.point - origin;
    const float d = glm::length(to);
    if (!(d > 0.0f)) continue;
    const glm::vec3 wi = to / d;
    const float cos_x = glm::dot(n, wi);
    if (cos_x <= 0.0f || glm::dot(wi, t.face[i]) <= 0.0f) continue;
    ++rays;
    const Landing l = land_ray(b, layout, t, Ray{origin, 0.0f, wi}, t.face[i]);
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
bool final_gather(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t,
                  const TexelGatherSettings& s, ThreadPool& pool, const ProgressCallback& progress,
                  const std::vector<std::size_t>& mine, const GatherSource& src, const TexelEmitters* emitters,
                  const KeptRays& k, std::vector<glm::vec3>& e, std::vector<glm::vec3>& sky,
                  std::vector<float>& variance, std::vector<std::uint64_t>& rays_of) {
  const auto nf = static_cast<std::size_t>(s.gather_rays);
  const auto ne = emitters ? static_cast<std::size_t>(s.emitter_rays) : std::size_t{0};
  // Both estimate T(E_d + E): weighted by their rays (the sky by the cosine rays alone).
  // With emitter rays the kept rays are left out: read at their landing texels without MIS
  // weights (their hit points are not kept), they would bring back the cosine rays' noise
  // (on the skylit room: 95th-percentile texel 0.36 with them, 0.23 without).
  const double w_solve = ne > 0 ? 0.0 : static_cast<double>(k.per_texel) / static_cast<double>(k.per_texel + nf);
  const double w_sky = static_cast<double>(k.per_texel) / static_cast<double>(k.per_texel + nf);
  // The mean's variance: the kept rays spread as the cosine rays do, so with them it is the
  // fresh rays' spread over all the rays.
  const double rays = static_cast<double>(nf + ne + (ne > 0 ? 0 : k.per_texel));
  std::vector<glm::vec3> gathered(e.size(), glm::vec3(0.0f));
  sky.assign(e.size(), glm::vec3(0.0f));
  const bool done = pool.parallel_for_with_progress(mine.size(), progress, [&](std::size_t m) {
    const std::size_t w = mine[m];
    const std::uint32_t i = t.work[w];
    const FreshGather g = gather_texel(b, layout, t, s, src, emitters, i, rays_of[w]);
    gathered[i] = glm::vec3(w_solve * glm::dvec3(e[i]) + (1.0 - w_solve) * g.irradiance);
    sky[i] = glm::vec3(w_sky * glm::dvec3(k.sky[i]) + (1.0 - w_sky) * static_cast<double>(kPi) * g.sky);
    variance[i] = static_cast<float>(g.ray_variance / rays);
  });
  e = std::move(gathered);
  return done;
}

// Step 4 on both filtered fields (indirect and the baked direct light): the denoiser, then
// the filter, as the settings ask.
void filter_result(const AtlasTexels& tx, const TexelTable& t, const TexelGatherSettings& s, float texel_m,
                   ThreadPool& pool, TexelGatherResult& out) {
  if (s.denoise_passes > 0 && texel_m > 0.0f) {
    std::vector<glm::vec3>* const fields[] = {&out.indirect, &out.baked_direct};
    denoise_world(tx, t.work, out.hidden, texel_m, {.passes = s.denoise_passes, .value_sigma = s.denoise_sigma}, pool,
                  out.variance, fields);
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

  // Step 1.
  auto t0 = Clock::now();
  if (!pool.parallel_for_with_progress(work, phase(0.0, 0.15), [&](std::size_t w) {
        const std::uint32_t i = t.work[w];
        Pcg32 rng = Pcg32::for_item(s.seed, stream_id(i, kDirectStream));
        const DirectAt d = direct_at(b, tx.position[i], tx.normal[i], t.face[i], s.direct_samples, rng, &rays_of[w]);
        out.direct[i] = d.live;
        out.baked_direct[i] = d.unlit;
      }))
    return engine::cancelled_error("light-atlas gather");
  out.direct_seconds = seconds_since(t0);

  // Step 2. Every texel reflects the direct light of the lights, of the emitters and of the sky.
  t0 = Clock::now();
  KeptRays kept;
  if (!cast_kept_rays(b, layout, t, s, pool, phase(0.15, 0.45), rays_of, kept))
    return engine::cancelled_error("light-atlas gather");
  std::vector<glm::vec3> emitted(n, glm::vec3(0.0f));
  for (std::uint32_t i : t.work) emitted[i] = out.direct[i] + out.baked_direct[i] + kept.sky[i];
  std::vector<glm::vec3>& e = out.indirect;
  out.iterations = solve_kept_rays(t, kept, emitted, s.bounces, pool, e);
  out.solve_seconds = seconds_since(t0);
  if (s.progress && !s.progress(0.5)) return engine::cancelled_error("light-atlas gather");

  // Step 3.
  t0 = Clock::now();
  const float texel_m = layout.texels_per_metre > 0.0f ? 1.0f / layout.texels_per_metre : 0.0f;
  const bool filtering = s.filter_radius_texels > 0.0f && texel_m > 0.0f;
  const float radius_m = s.filter_radius_texels * texel_m;
  std::vector<glm::vec3> sky = kept.sky;
  if (s.gather_rays > 0 || s.emitter_rays > 0) {
    // The gather reads the solve's light filtered too: its noise would otherwise come back
    // as blotches a few texels wide (a bright texel lights its neighbours' rays).
    const std::vector<glm::vec3> source =
        filtering ? filter_world(tx, t.work, e, kept.hidden, radius_m, texel_m, pool) : e;
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
    src.sharp = sharp_pixels(lit, t.width, t.height);
    std::vector<std::uint64_t> gather_rays_of(work, 0);
    if (!final_gather(b, layout, t, s, pool, phase(0.5, 0.95), s.shard.items(work), src,
                      emitters ? &*emitters : nullptr, kept, e, sky, out.variance, gather_rays_of))
      return engine::cancelled_error("light-atlas gather");
    for (std::uint64_t r : gather_rays_of) out.own_rays += r;
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
  std::vector<std::uint64_t> rays_of(table->work.size(), 0);
  TexelGatherSettings s;
  s.solve_rays = rays;
  s.seed = seed;
  KeptRays kept;
  cast_kept_rays(b, layout, *table, s, pool, {}, rays_of, kept);
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
