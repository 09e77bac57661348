#include "light_atlas/texel_landing.h"

#include <engine/sky.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/color.h"
#include "light_atlas/texel_direct.h"
#include "light_atlas/texel_sampling.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"

namespace gi {
namespace {

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
void mark_unseen(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const glm::vec3& p,
                 float distance, Landing& l) {
  const Footprint f = footprint_at(t.width, t.height, l.uv);
  const bool near = distance < t.near_m;
  std::uint32_t checked[5] = {l.texel, kDark, kDark, kDark, kDark};
  const bool moved = (lt.pixels[l.pixel].bits & LandingTable::kMoved) != 0;
  bool unseen[5] = {(near || moved) && sample_unseen(b, t, p, l.side, l.texel)};
  for (int k = 0; k < 4; ++k) {
    const LandingTable::Pixel& corner = lt.pixels[f.pixel[k]];
    const std::uint32_t j = LandingTable::texel_of(corner);
    if (j == kDark || !(near || (corner.bits & LandingTable::kMoved) != 0)) continue;
    int c = 0;
    while (c <= k && checked[c] != j && checked[c] != kDark) ++c;
    if (checked[c] != j) checked[c] = j, unseen[c] = sample_unseen(b, t, p, l.side, j);
    if (unseen[c]) l.unseen_corners = static_cast<std::uint8_t>(l.unseen_corners | (1u << k));
  }
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

// The atlas pixel under uv (the landing's `pixel`).
std::uint32_t pixel_at(const TexelTable& t, glm::vec2 uv) {
  const int x = std::clamp(static_cast<int>(uv.x * static_cast<float>(t.width)), 0, t.width - 1);
  const int y = std::clamp(static_cast<int>(uv.y * static_cast<float>(t.height)), 0, t.height - 1);
  return static_cast<std::uint32_t>(static_cast<std::size_t>(y) * static_cast<std::size_t>(t.width) +
                                    static_cast<std::size_t>(x));
}

glm::vec2 uv_at(const LandingTable::Triangle& tri, glm::vec2 barycentric) {
  const float u = barycentric.x, v = barycentric.y;
  return (1.0f - u - v) * tri.uv[0] + u * tri.uv[1] + v * tri.uv[2];
}

// land_ray of `ray` whose hit is `h`; with `corners` false, Landing::unseen_corners stays 0
// (its visibility rays are cast only for the reads that use them).
Landing land_hit(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const Ray& ray, const Hit& h,
                 const glm::vec3& from, bool corners) {
  if (!h.valid()) return {};
  const LandingTable::Triangle& tri = lt.triangle_of(h);
  const float cos_surface = glm::dot(tri.face_normal, ray.direction);
  if (!(cos_surface < 0.0f) && tri.double_sided == 0) return {.texel = kBack};
  const glm::vec3 side = cos_surface < 0.0f ? tri.face_normal : -tri.face_normal;
  if (h.t < t.gap_m && std::fabs(glm::dot(tri.face_normal, from)) > 0.9f && gap_is_covered(b, t, ray, h, side))
    return {.texel = kBack};
  Landing l;
  l.triangle = tri.triangle;
  l.barycentric = h.barycentric;
  l.side = side;
  l.uv = uv_at(tri, h.barycentric);
  l.pixel = pixel_at(t, l.uv);
  l.texel = LandingTable::texel_of(lt.pixels[l.pixel]);
  if (corners && l.texel != kDark) mark_unseen(b, lt, t, ray.origin + h.t * ray.direction, h.t, l);
  l.distance = h.t;
  l.cos_surface = std::fabs(cos_surface);
  return l;
}

Landing land(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const Ray& ray,
             const glm::vec3& from, bool corners) {
  return land_hit(b, lt, t, ray, b.caster->intersect_without_normal(ray), from, corners);
}

// Up to kBatch rays cast before any of them lands: their triangles' records, then their
// pixels' records (and, for the reads, the shading triangle and the footprint's other rows)
// are prefetched, so that the landings' cache misses overlap instead of following each other.
constexpr std::size_t kBatch = 16;

template <typename Land>
void land_batched(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, std::span<const Ray> rays,
                  bool corners, Land&& land_one) {
  std::array<Hit, kBatch> hits;
  for (std::size_t first = 0; first < rays.size(); first += kBatch) {
    const std::size_t n = std::min(kBatch, rays.size() - first);
    for (std::size_t r = 0; r < n; ++r) {
      hits[r] = b.caster->intersect_without_normal(rays[first + r]);
      if (hits[r].valid()) __builtin_prefetch(&lt.triangle_of(hits[r]));
    }
    for (std::size_t r = 0; r < n; ++r) {
      if (!hits[r].valid()) continue;
      const LandingTable::Triangle& tri = lt.triangle_of(hits[r]);
      const std::size_t p = pixel_at(t, uv_at(tri, hits[r].barycentric));
      __builtin_prefetch(&lt.pixels[p]);
      if (!corners) continue;
      const auto w = static_cast<std::size_t>(t.width);
      if (p >= w) __builtin_prefetch(&lt.pixels[p - w]);
      if (p + w < lt.pixels.size()) __builtin_prefetch(&lt.pixels[p + w]);
      __builtin_prefetch(&b.index.triangles[tri.triangle]);
    }
    for (std::size_t r = 0; r < n; ++r) land_one(first + r, hits[r]);
  }
}

}  // namespace

glm::vec3 landing_shading_normal(const ShadingTriangle& tri, glm::vec2 barycentric, const glm::vec3& side) {
  const float u = barycentric.x, v = barycentric.y;
  glm::vec3 n = (1.0f - u - v) * tri.n0 + u * tri.n1 + v * tri.n2;
  n = glm::dot(n, n) > 0.0f && std::isfinite(glm::dot(n, n)) ? glm::normalize(n) : side;
  if (glm::dot(side, tri.face_normal) < 0.0f) n = -n;  // a double-sided surface seen from behind
  return glm::dot(n, side) > 0.0f ? n : side;
}

engine::Result<LandingTable> landing_table(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t) {
  const std::size_t n = t.redirect.size();
  if (n >= LandingTable::kTexelMask)
    return engine::invalid_request("the light atlas's landing table: 2^30 atlas texels or more");
  LandingTable lt;
  for (std::size_t m = 0; m < layout.meshes.size(); ++m) {
    const AtlasMeshUv& mu = layout.meshes[m];
    const auto first = static_cast<std::uint32_t>(lt.triangles.size());
    lt.first.push_back(first);
    const std::uint32_t shading_first = b.index.instance_first[b.static_instance[m]];
    for (std::size_t p = 0; p < mu.indices.size() / 3; ++p) {
      const std::uint32_t triangle = shading_first + static_cast<std::uint32_t>(p);
      const ShadingTriangle& tri = b.index.triangles[triangle];
      LandingTable::Triangle& r = lt.triangles.emplace_back();
      r.face_normal = tri.face_normal;
      r.double_sided = b.scene.materials[tri.material].double_sided ? 1 : 0;
      r.triangle = triangle;
      for (int k = 0; k < 3; ++k) r.uv[k] = mu.uv1[mu.indices[3 * p + static_cast<std::size_t>(k)]];
    }
  }
  lt.pixels.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t j = t.redirect[i];
    if (j == kDark) continue;
    lt.pixels[i].bits = j | (t.moved[j] != 0 ? LandingTable::kMoved : 0u);
    lt.pixels[i].albedo = t.albedo[j];
  }
  return lt;
}

void mark_sharp(LandingTable& lt, const std::vector<std::uint8_t>& sharp) {
  for (std::size_t i = 0; i < lt.pixels.size() && i < sharp.size(); ++i)
    lt.pixels[i].bits = (lt.pixels[i].bits & ~LandingTable::kSharp) | (sharp[i] != 0 ? LandingTable::kSharp : 0u);
}

Landing land_ray(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const Ray& ray,
                 const glm::vec3& from) {
  return land(b, lt, t, ray, from, true);
}

void land_rays(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, std::span<const Ray> rays,
               const glm::vec3& from, std::span<Landing> out) {
  land_batched(b, lt, t, rays, true,
               [&](std::size_t r, const Hit& h) { out[r] = land_hit(b, lt, t, rays[r], h, from, true); });
}

void landings(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, std::span<const Ray> rays,
              const glm::vec3& from, std::span<std::uint32_t> out) {
  land_batched(b, lt, t, rays, false,
               [&](std::size_t r, const Hit& h) { out[r] = land_hit(b, lt, t, rays[r], h, from, false).texel; });
}

std::uint32_t landing(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const Ray& ray,
                      const glm::vec3& from, glm::vec2* uv) {
  // The kept rays read the texel alone: no corner of a bilinear read to check.
  const Landing l = land(b, lt, t, ray, from, false);
  if (uv && l.texel != kSky && l.texel != kBack) *uv = l.uv;
  return l.texel;
}

namespace {

// The bilinear read of `img` at a landing without the corners whose samples do not see the
// landing point (Landing::unseen_corners), renormalised; false (and 0) where none does.
bool read_seen_corners(const TexelTable& t, const std::vector<glm::vec3>& img, const Landing& l, glm::dvec3& out) {
  out = glm::dvec3(0.0);
  if (l.unseen_corners == 0) return out = glm::dvec3(bilinear(img, t.width, t.height, l.uv)), true;
  const Footprint f = footprint_at(t.width, t.height, l.uv);
  double weights = 0.0;
  for (int k = 0; k < 4; ++k) {
    if (l.unseen_corners & (1u << k)) continue;
    const double wk = static_cast<double>((k % 2 ? f.ax : 1.0f - f.ax) * (k / 2 ? f.ay : 1.0f - f.ay));
    out += wk * glm::dvec3(img[f.pixel[k]]), weights += wk;
  }
  if (!(weights > 0.0)) return out = glm::dvec3(0.0), false;
  out /= weights;
  return true;
}

// The point a ray landed on, and its shading normal on the side the ray came from, as the
// path tracer shades it (shading_brdf): turned over on the back of a double-sided surface,
// and the face's own normal where the interpolated one still points below the surface.
// Dabrovic Sponza has vertex normals opposite to their face (a column base's ledge): turned
// over, such a normal leant 50 degrees off the ledge, which then read a third of the sun
// the path tracer finds there.
struct LandingPoint {
  glm::vec3 p, n;
};

LandingPoint landing_point(const StaticBakeScene& b, const Landing& l) {
  const ShadingTriangle& tri = b.index.triangles[l.triangle];
  const float u = l.barycentric.x, v = l.barycentric.y;
  return {tri.p0 + u * tri.e1 + v * tri.e2, landing_shading_normal(tri, l.barycentric, l.side)};
}

glm::dvec3 read_at(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l, Pcg32& rng,
                   std::uint64_t& rays, int depth);

// The sky's and the indirect irradiance at a landing point `depth` levels down from stratified
// cosine rays (src.near_rays at the first level, src.near_deep_rays below it where set), each
// read where it lands as a fresh ray's landing is (read_at one level further down) or the sky
// where it escapes.
glm::dvec3 regather_at(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l,
                       const LandingPoint& at, Pcg32& rng, std::uint64_t& rays, int depth) {
  const glm::vec3 origin = offset_ray_origin(at.p, l.side);
  const auto m = static_cast<std::uint32_t>(depth > 1 && src.near_deep_rays > 0 ? src.near_deep_rays : src.near_rays);
  const float shift_y = rng.next_float();  // drawn first: see random.h
  const glm::vec2 shift(rng.next_float(), shift_y);
  glm::dvec3 sum(0.0);
  for (std::uint32_t r = 0; r < m; ++r) {
    const glm::vec2 u = hammersley(r, m, shift);
    const glm::vec3 wi = sample_cosine_hemisphere(at.n, u.x, u.y);
    if (glm::dot(wi, l.side) <= 0.0f) continue;
    ++rays;
    const Landing l2 = land(b, *src.table, t, Ray{origin, 0.0f, wi}, l.side, true);
    if (l2.texel == kSky)
      sum += std::numbers::pi * glm::dvec3(engine::sky_radiance(b.scene.sky_radiance, b.scene.sky_gradient, wi));
    else if (l2.texel < kBack)
      sum += read_at(b, t, src, l2, rng, rays, depth + 1);
  }
  return sum / static_cast<double>(m);
}

// A landing's light read from the texels (no regather): the rest bilinearly, the lights'
// direct light at the point where the settings ask (read_landing's rules).
glm::dvec3 read_texels(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l,
                       Pcg32& rng, std::uint64_t& rays) {
  // l.texel is the pixel's redirect: the pixel's record holds its albedo.
  const LandingTable::Pixel& px = src.table->pixels[l.pixel];
  const bool sharp = (px.bits & LandingTable::kSharp) != 0;
  glm::dvec3 rest(0.0);
  if (!sharp && src.punctual_everywhere) {
    if (read_seen_corners(t, src.without_punctual, l, rest)) {
      const LandingPoint at = landing_point(b, l);
      const DirectAt d = direct_at(b, at.p, at.n, l.side, 1, rng, &rays, DirectLights::Punctual);
      return rest + glm::dvec3(px.albedo * d.live);
    }
    // No corner sees the point: every light's direct light there is all the read takes.
  } else if (read_seen_corners(t, sharp ? src.without_lights : src.reflected, l, rest) && !sharp) {
    return rest;
  }
  // Where no corner sees the point, the lights' direct light there is all the read takes.
  const LandingPoint at = landing_point(b, l);
  const DirectAt d = direct_at(b, at.p, at.n, l.side, 1, rng, &rays);
  const glm::dvec3 lights(px.albedo * (d.live + d.unlit));
  return rest + lights;
}

// The read at a landing `depth` levels down (1: a fresh ray's): a near landing, while the
// regather's depth allows, takes every light's direct light and, from a regather of its own,
// the sky and the indirect light at its point; any other reads the texels.
glm::dvec3 read_at(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l, Pcg32& rng,
                   std::uint64_t& rays, int depth) {
  if (src.near_rays > 0 && l.distance < src.near_m && depth <= src.near_depth) {
    const LandingPoint at = landing_point(b, l);
    const glm::dvec3 rest = regather_at(b, t, src, l, at, rng, rays, depth);
    const DirectAt d = direct_at(b, at.p, at.n, l.side, 1, rng, &rays);
    return glm::dvec3(src.table->pixels[l.pixel].albedo) * (rest + glm::dvec3(d.live + d.unlit));
  }
  return read_texels(b, t, src, l, rng, rays);
}

}  // namespace

glm::dvec3 read_landing(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l,
                        Pcg32& rng, std::uint64_t& rays) {
  return read_at(b, t, src, l, rng, rays, 1);
}

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

}  // namespace gi
