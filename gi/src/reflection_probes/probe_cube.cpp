#include "reflection_probes/probe_cube.h"

#include <engine/gltf_brdf.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "core/bit_reverse.h"
#include "core/thread_pool.h"
#include "raytrace/reference_brdf.h"

namespace gi {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Texel of face coordinate u in [-1, 1] on a face of size s.
int texel_of(float u, int s) {
  const int x = static_cast<int>(std::floor((u + 1.0f) * 0.5f * static_cast<float>(s)));
  return std::clamp(x, 0, s - 1);
}

glm::vec3 lookup_level(const std::vector<glm::vec3>& texels, int s, const glm::vec3& d) {
  const CubeCoordinate c = cube_coordinate(d);
  return texels[cube_texel_index(c.face, texel_of(c.u, s), texel_of(c.v, s), s)];
}

// Level 0 and its 2 x 2 box averages down to one texel per face: what the prefilter's
// samples read, each at the level matching its share of the sphere.
std::vector<std::vector<glm::vec3>> box_chain(const ProbeCube& cube) {
  std::vector<std::vector<glm::vec3>> chain{cube.levels[0]};
  for (int s = cube.size / 2; s >= 1; s /= 2) {
    const std::vector<glm::vec3>& fine = chain.back();
    std::vector<glm::vec3> coarse(static_cast<std::size_t>(6 * s * s));
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x)
          coarse[cube_texel_index(f, x, y, s)] = 0.25f * (fine[cube_texel_index(f, 2 * x, 2 * y, 2 * s)] +
                                                          fine[cube_texel_index(f, 2 * x + 1, 2 * y, 2 * s)] +
                                                          fine[cube_texel_index(f, 2 * x, 2 * y + 1, 2 * s)] +
                                                          fine[cube_texel_index(f, 2 * x + 1, 2 * y + 1, 2 * s)]);
    chain.push_back(std::move(coarse));
  }
  return chain;
}

// Van der Corput's radical inverse in base 2: the bits of i mirrored about the binary point.
float radical_inverse(std::uint32_t i) { return static_cast<float>(reverse_bits(i)) * 2.3283064365386963e-10f; }

struct LobeSample {
  glm::vec3 tangent_h{0.0f};  ///< The half vector in the frame (t, b, n).
  float lod = 0.0f;           ///< Chain level the sample reads (fractional).
};

// The GGX half vectors of one level's lobe and the chain level each reads; the same for
// every texel (the lobe is rotated onto the texel's direction).
std::vector<LobeSample> lobe_samples(float alpha, int samples, int size0, int chain_levels) {
  std::vector<LobeSample> out;
  const float texel_sr = 4.0f * kPi / (6.0f * static_cast<float>(size0 * size0));
  for (int i = 0; i < samples; ++i) {
    const float phi = 2.0f * kPi * (static_cast<float>(i) + 0.5f) / static_cast<float>(samples);
    const float xi = radical_inverse(static_cast<std::uint32_t>(i));
    const float cos_h = std::sqrt((1.0f - xi) / (1.0f + (alpha * alpha - 1.0f) * xi));
    const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos_h * cos_h));
    LobeSample s;
    s.tangent_h = glm::vec3(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
    // pdf of l = D(n.h) (n.h) / (4 v.h) = D / 4 with v = n.
    const float pdf = engine::gltf_ggx_distribution(cos_h, alpha) * 0.25f;
    const float sample_sr = 1.0f / (static_cast<float>(samples) * std::max(pdf, 1e-12f));
    s.lod = std::clamp(0.5f * std::log2(sample_sr / texel_sr) + 1.0f, 0.0f, static_cast<float>(chain_levels - 1));
    out.push_back(s);
  }
  return out;
}

glm::vec3 read_chain(const std::vector<std::vector<glm::vec3>>& chain, int size0, float lod, const glm::vec3& d) {
  const int lo = static_cast<int>(std::floor(lod));
  const int hi = std::min(lo + 1, static_cast<int>(chain.size()) - 1);
  const float f = lod - static_cast<float>(lo);
  const glm::vec3 a = lookup_level(chain[static_cast<std::size_t>(lo)], cube_level_size(size0, lo), d);
  if (f <= 0.0f || hi == lo) return a;
  return a + f * (lookup_level(chain[static_cast<std::size_t>(hi)], cube_level_size(size0, hi), d) - a);
}

// Level texels read bilinearly at face coordinate (u, v), edge texels clamped.
template <typename T>
T bilinear_level(const std::vector<T>& texels, int s, const CubeCoordinate& c) {
  const float fx = (c.u + 1.0f) * 0.5f * static_cast<float>(s) - 0.5f;
  const float fy = (c.v + 1.0f) * 0.5f * static_cast<float>(s) - 0.5f;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0);
  const auto at = [&](int x, int y) {
    return texels[cube_texel_index(c.face, std::clamp(x, 0, s - 1), std::clamp(y, 0, s - 1), s)];
  };
  return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), tx), glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), tx), ty);
}

}  // namespace

glm::vec3 cube_lookup_trilinear(const ProbeCube& cube, float lod, const glm::vec3& d) {
  const int top = static_cast<int>(cube.levels.size()) - 1;
  const float l = std::clamp(lod, 0.0f, static_cast<float>(std::max(top, 0)));
  const int lo = static_cast<int>(std::floor(l)), hi = std::min(lo + 1, top);
  const CubeCoordinate c = cube_coordinate(d);
  const glm::vec3 a = bilinear_level(cube.levels[static_cast<std::size_t>(lo)], cube_level_size(cube.size, lo), c);
  if (hi == lo) return a;
  const glm::vec3 b = bilinear_level(cube.levels[static_cast<std::size_t>(hi)], cube_level_size(cube.size, hi), c);
  return glm::mix(a, b, l - static_cast<float>(lo));
}

// Where the ray from p (clamped onto the box) along r (not zero) leaves [box_min, box_max].
glm::vec3 box_exit(const glm::vec3& p, const glm::vec3& r, const glm::vec3& box_min, const glm::vec3& box_max) {
  const glm::vec3 q = glm::clamp(p, box_min, box_max);
  float t = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (r[a] > 0.0f) t = std::min(t, (box_max[a] - q[a]) / r[a]);
    if (r[a] < 0.0f) t = std::min(t, (box_min[a] - q[a]) / r[a]);
  }
  return q + t * r;
}

float cube_distance_bilinear(const ProbeCube& cube, const glm::vec3& d) {
  if (cube.distance.empty()) return kProbeFarDistance;
  return bilinear_level(cube.distance, cube_distance_size(cube), cube_coordinate(d));
}

float probe_visibility_weight(const ProbeCube& cube, const glm::vec3& centre, const glm::vec3& p) {
  if (cube.distance.empty()) return 1.0f;
  const glm::vec3 x = p - centre;
  const float length = glm::length(x);
  if (!(length > 0.0f)) return 1.0f;
  const float seen = cube_distance_bilinear(cube, x);
  return seen >= length * (1.0f - kProbeBoxSideTolerance) - kProbeSeesSlackM ? 1.0f : kProbeHiddenWeight;
}

CubeDistanceFootprint cube_distance_footprint(const ProbeCube& cube, const glm::vec3& d) {
  if (cube.distance.empty()) return {kProbeFarDistance, kProbeFarDistance};
  const CubeCoordinate c = cube_coordinate(d);
  const int s = cube_distance_size(cube);
  const int x0 = static_cast<int>(std::floor((c.u + 1.0f) * 0.5f * static_cast<float>(s) - 0.5f));
  const int y0 = static_cast<int>(std::floor((c.v + 1.0f) * 0.5f * static_cast<float>(s) - 0.5f));
  CubeDistanceFootprint f{std::numeric_limits<float>::infinity(), 0.0f};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const float t =
          cube.distance[cube_texel_index(c.face, std::clamp(x0 + i, 0, s - 1), std::clamp(y0 + j, 0, s - 1), s)];
      f.nearest = std::min(f.nearest, t), f.farthest = std::max(f.farthest, t);
    }
  return f;
}

namespace {

// The box-first test at an opening's rim (kProbeRimNearest): the ray x + t r leaves the box at
// t_exit, where the bilinear mean distance is `mean`. Whether the exit's four distance texels
// that saw the box's side there weigh at least half, and the ray passes behind that side (at the
// exit, or within the tolerance past it, as distance_corrected_direction's own test).
bool rim_is_side(const ProbeCube& cube, const glm::vec3& x, const glm::vec3& r, float t_exit, float mean,
                 float tolerance) {
  const glm::vec3 q = x + t_exit * r;
  const CubeDistanceFootprint f = cube_distance_footprint(cube, q);
  if (mean > 0.5f * (f.nearest + f.farthest)) return false;
  const float g = glm::length(q) - f.nearest;
  if (g >= 0.0f) return g <= tolerance;
  const glm::vec3 beyond = x + (t_exit + tolerance) * r;
  return g >= -tolerance && glm::length(beyond) >= cube_distance_footprint(cube, beyond).nearest;
}

// Whether the probe saw beyond its box's side in direction d: the captured distance more than the
// box-side tolerance past where the ray from the centre along d leaves the box (an opening).
bool beyond_box_side(const ProbeCube& cube, const glm::vec3& d, const glm::vec3& centre, const glm::vec3& box_min,
                     const glm::vec3& box_max) {
  const glm::vec3 dn = glm::normalize(d);
  const float side = glm::length(box_exit(centre, dn, box_min, box_max) - centre);
  return cube_distance_bilinear(cube, dn) > side * (1.0f + kProbeBoxSideTolerance);
}

// The level of a box-filtered chain whose texels span a sample's solid angle (sr), + 1 (Colbert
// and Krivanek's rule; probe_lobe_radiance's `chain`).
float chain_level(const ProbeCube& chain, float sample_sr) {
  const float texel_sr = 4.0f * kPi / (6.0f * static_cast<float>(chain.size * chain.size));
  return std::max(0.5f * std::log2(sample_sr / texel_sr) + 1.0f, 0.0f);
}

}  // namespace

// Long because the box-first test and the search share g, the search's scale and the state the
// search starts from (t0, t_lo, g_lo, in_front, the step scale): split, those five would travel
// between the two as parameters and results.
glm::vec3 distance_corrected_direction(const ProbeCube& cube, const glm::vec3& p, const glm::vec3& r,
                                       const glm::vec3& centre, const glm::vec3& box_min, const glm::vec3& box_max,
                                       float box_side_tolerance, bool rim_nearest) {
  const glm::vec3 boxed = box_projected_direction(p, r, centre, box_min, box_max);
  if (cube.distance.empty()) return boxed;
  const glm::vec3 x = p - centre;
  const float scale = std::max(glm::length(x), kProbeMinSearchScaleM);
  // g(t) = |x + t r| - distance(x + t r): negative in front of the surface the probe saw
  // along that direction, positive behind it. The ray's points t = scale a / (1 - a), a in
  // (0, 1), cover it to infinity with steps that grow with the distance.
  const auto g = [&](float t) {
    const glm::vec3 q = x + t * r;
    return glm::length(q) - cube_distance_bilinear(cube, q);
  };
  float t_lo = 0.0f, g_lo = 0.0f, t0 = 0.0f, step_scale = scale;
  bool in_front = false;
  if (box_side_tolerance >= 0.0f) {
    // The box first: where the probe saw a surface at the box's side, the box's answer is the
    // ray's own hit; where it saw farther (an opening), search on from the side.
    // A surface at the side is one the ray passes behind there: just past the exit (a ray that
    // grazes a floor beyond an open side stays in front of it).
    const float t_exit = glm::dot(box_exit(p, r, box_min, box_max) - p, r);
    const float g_exit = g(t_exit), exit_distance = glm::length(x + t_exit * r);
    const float tolerance = box_side_tolerance * exit_distance;
    // An object the ray passes clearly behind (by more than the tolerance) before the exit:
    // the search as before.
    bool blocked = false, front = false;
    for (int k = 1; k <= kProbeSearchSteps && !blocked; ++k) {
      const float a = static_cast<float>(k) / static_cast<float>(kProbeSearchSteps + 1);
      const float t = scale * a / (1.0f - a);
      if (t >= t_exit) break;
      const float gt = g(t);
      if (gt < 0.0f)
        front = true;
      else if (front && gt > box_side_tolerance * glm::length(x + t * r))
        blocked = true;
    }
    if (!blocked && g_exit >= 0.0f && g_exit <= tolerance) return boxed;
    if (!blocked && g_exit < 0.0f && g_exit >= -tolerance && g(t_exit + tolerance) >= 0.0f) return boxed;
    // At an opening's rim the mean distances mix the side's and the far room's: where the
    // exit's texels that saw the side weigh at least half (the mean nearer their distance than the
    // far ones'), the same test on the nearest of them (a thin jamb beside the opening is the side).
    if (rim_nearest && !blocked && g_exit < -tolerance &&
        rim_is_side(cube, x, r, t_exit, exit_distance - g_exit, tolerance))
      return boxed;
    if (!blocked && g_exit < 0.0f)
      t0 = t_exit, t_lo = t_exit, g_lo = g_exit, in_front = true,
      step_scale = std::max(exit_distance, kProbeMinSearchScaleM);
  }
  for (int k = 1; k <= kProbeSearchSteps; ++k) {
    const float a = static_cast<float>(k) / static_cast<float>(kProbeSearchSteps + 1);
    const float t = t0 + step_scale * a / (1.0f - a), gt = g(t);
    if (gt < 0.0f) {
      t_lo = t, g_lo = gt, in_front = true;
      continue;
    }
    if (!in_front) continue;
    // The ray passed behind the captured surface between t_lo and t: secant steps.
    float t_hi = t, g_hi = gt;
    for (int i = 0; i < kProbeSecantSteps; ++i) {
      const float tm = t_lo + (t_hi - t_lo) * g_lo / (g_lo - g_hi), gm = g(tm);
      if (gm < 0.0f)
        t_lo = tm, g_lo = gm;
      else
        t_hi = tm, g_hi = gm;
    }
    const float tm = t_lo + (t_hi - t_lo) * g_lo / (g_lo - g_hi);
    const glm::vec3 q = x + tm * r;
    return glm::dot(q, q) > 1e-12f ? q : r;
  }
  // Never in front of the captured surface (the point is hidden from the probe's centre):
  // the box's answer; never behind one: the ray leaves the scene, its direction at infinity.
  return in_front ? r : boxed;
}

ProbeCube box_filtered_chain(const ProbeCube& cube) {
  ProbeCube out;
  out.size = cube.size;
  out.levels = box_chain(cube);
  out.distance = cube.distance;
  out.distance_size = cube.distance_size;
  return out;
}

int full_mip_count(int size) { return size < 1 ? 0 : std::bit_width(static_cast<unsigned>(size)); }

ProbeCube make_probe_cube(int size, int levels) {
  ProbeCube c;
  c.size = size;
  for (int m = 0; m < levels; ++m) {
    const int s = cube_level_size(size, m);
    c.levels.emplace_back(static_cast<std::size_t>(6 * s * s), glm::vec3(0.0f));
  }
  return c;
}

glm::vec3 cube_direction(int face, float u, float v) {
  glm::vec3 d;
  switch (face) {
    case 0:
      d = glm::vec3(1.0f, -v, -u);
      break;
    case 1:
      d = glm::vec3(-1.0f, -v, u);
      break;
    case 2:
      d = glm::vec3(u, 1.0f, v);
      break;
    case 3:
      d = glm::vec3(u, -1.0f, -v);
      break;
    case 4:
      d = glm::vec3(u, -v, 1.0f);
      break;
    default:
      d = glm::vec3(-u, -v, -1.0f);
      break;
  }
  return glm::normalize(d);
}

glm::vec3 cube_texel_direction(int face, int x, int y, int s) {
  const auto fs = static_cast<float>(s);
  return cube_direction(face, (2.0f * static_cast<float>(x) + 1.0f) / fs - 1.0f,
                        (2.0f * static_cast<float>(y) + 1.0f) / fs - 1.0f);
}

CubeCoordinate cube_coordinate(const glm::vec3& d) {
  const glm::vec3 a = glm::abs(d);
  CubeCoordinate c;
  float sc = 0.0f, tc = 0.0f, ma = 1.0f;
  if (a.x >= a.y && a.x >= a.z) {
    c.face = d.x > 0.0f ? 0 : 1;
    ma = a.x;
    sc = d.x > 0.0f ? -d.z : d.z;
    tc = -d.y;
  } else if (a.y >= a.z) {
    c.face = d.y > 0.0f ? 2 : 3;
    ma = a.y;
    sc = d.x;
    tc = d.y > 0.0f ? d.z : -d.z;
  } else {
    c.face = d.z > 0.0f ? 4 : 5;
    ma = a.z;
    sc = d.z > 0.0f ? d.x : -d.x;
    tc = -d.y;
  }
  c.u = sc / ma;
  c.v = tc / ma;
  return c;
}

float cube_texel_solid_angle(int x, int y, int s) {
  // Integral of the face's area element: A(u, v) = atan2(u v, sqrt(u^2 + v^2 + 1)).
  const auto area = [](float u, float v) { return std::atan2(u * v, std::sqrt(u * u + v * v + 1.0f)); };
  const auto fs = static_cast<float>(s);
  const float u0 = 2.0f * static_cast<float>(x) / fs - 1.0f, u1 = 2.0f * static_cast<float>(x + 1) / fs - 1.0f;
  const float v0 = 2.0f * static_cast<float>(y) / fs - 1.0f, v1 = 2.0f * static_cast<float>(y + 1) / fs - 1.0f;
  return area(u0, v0) - area(u0, v1) - area(u1, v0) + area(u1, v1);
}

glm::vec3 cube_lookup(const ProbeCube& cube, int level, const glm::vec3& d) {
  return lookup_level(cube.levels[static_cast<std::size_t>(level)], cube_level_size(cube.size, level), d);
}

glm::vec3 box_projected_direction(const glm::vec3& p, const glm::vec3& r, const glm::vec3& centre,
                                  const glm::vec3& box_min, const glm::vec3& box_max) {
  const glm::vec3 d = box_exit(p, r, box_min, box_max) - centre;
  const float len = glm::length(d);
  return len > 1e-6f ? d / len : glm::normalize(r);
}

int probe_lobe_sample_count(int samples, int most, float nv) {
  const int base = std::clamp(samples, 1, kProbeMaxLobeSamples);
  const int cap = std::clamp(most, base, kProbeMaxLobeSamples);
  const float c = std::clamp(nv, 0.0f, 1.0f);
  int count = base;
  while (count * 2 <= cap && static_cast<float>(count) * c < static_cast<float>(base)) count *= 2;
  return count;
}

glm::vec3 probe_lobe_radiance(const ProbeCube& cube, const engine::GltfBrdf& brdf, const glm::vec3& p,
                              const glm::vec3& n, const glm::vec3& v, int samples, const glm::vec3& centre,
                              const glm::vec3& box_min, const glm::vec3& box_max, bool box_only, const ProbeCube* chain,
                              float box_side_tolerance, bool rim_nearest, float opening_level_bias, float level_bias) {
  const int count = std::clamp(samples, 1, kProbeMaxLobeSamples);
  const float alpha = brdf.alpha, a2 = alpha * alpha;
  const float nv = std::max(glm::dot(n, v), 1e-4f);
  const auto corrected = [&](const glm::vec3& l) {
    return box_only
               ? box_projected_direction(p, l, centre, box_min, box_max)
               : distance_corrected_direction(cube, p, l, centre, box_min, box_max, box_side_tolerance, rim_nearest);
  };
  // The frame (t, b, n) with v in the (t, n) plane; the shader builds the same one.
  glm::vec3 t = v - nv * n;
  if (glm::dot(t, t) < 1e-8f)
    t = glm::cross(std::abs(n.z) < 0.999f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(1.0f, 0.0f, 0.0f), n);
  t = glm::normalize(t);
  const glm::vec3 b = glm::cross(n, t);
  // The view stretched by alpha (the hemisphere configuration of the visible normals).
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * glm::dot(v, t), 0.0f, nv));
  const float g1 = 2.0f * nv / (nv + std::sqrt(a2 + (1.0f - a2) * nv * nv));
  const float top_level = static_cast<float>(cube.levels.size() - 1);
  const auto fn = static_cast<float>(count);
  const glm::vec3 f_dielectric_scale = (1.0f - brdf.metallic) * brdf.specular_weight * glm::vec3(1.0f);
  glm::vec3 sum(0.0f), weight(0.0f);
  for (int i = 0; i < count; ++i) {
    const float phi = 2.0f * kPi * (static_cast<float>(i) + 0.5f) / fn;
    const float u = radical_inverse(static_cast<std::uint32_t>(i)) + 0.5f / fn;
    const float z = (1.0f - u) * (1.0f + vh.z) - vh.z;
    const float sin_t = std::sqrt(std::clamp(1.0f - z * z, 0.0f, 1.0f));
    const glm::vec3 c = glm::vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), z) + vh;
    const glm::vec3 hl = glm::normalize(glm::vec3(alpha * c.x, alpha * c.y, std::max(c.z, 0.0f)));
    const glm::vec3 h = hl.x * t + hl.y * b + hl.z * n;
    const float vdh = glm::dot(v, h);
    const glm::vec3 l = 2.0f * vdh * h - v;
    const float nl = glm::dot(n, l);
    if (!(nl > 0.0f) || !(vdh > 0.0f)) continue;
    // pdf(l) = G1(v) D(h) / (4 n.v); the sample stands for 1 / (count pdf) sr of the sphere,
    // a patch narrower across the reflection's plane than along it by v.h: the level read is
    // the one prefiltered with the GGX lobe (solid angle about 4 pi alpha^2) of that width.
    const float pdf = g1 * engine::gltf_ggx_distribution(std::clamp(hl.z, 0.0f, 1.0f), alpha) / (4.0f * nv);
    const float alpha_m = std::sqrt(vdh / (fn * std::max(pdf, 1e-12f) * 4.0f * kPi));
    float lod = chain ? chain_level(*chain, 1.0f / (fn * std::max(pdf, 1e-12f)))
                      : std::max(std::sqrt(alpha_m) * top_level - level_bias, 0.0f);
    const float w = engine::gltf_schlick_weight(vdh);
    const glm::vec3 f = f_dielectric_scale * (brdf.dielectric_f0 + (1.0f - brdf.dielectric_f0) * w) +
                        brdf.metallic * (brdf.base_color + (1.0f - brdf.base_color) * w);
    // The BRDF-sample weight F G2 / G1 up to the factor the samples share (G1, 4 n.v).
    const glm::vec3 wi = f * (engine::gltf_smith_visibility(nv, nl, alpha) * nl);
    const glm::vec3 d = corrected(l);
    if (opening_level_bias > 0.0f && !box_only && !cube.distance.empty() &&
        beyond_box_side(cube, d, centre, box_min, box_max))
      lod = std::max(lod - opening_level_bias, 0.0f);
    sum += wi * cube_lookup_trilinear(chain ? *chain : cube, lod, d);
    weight += wi;
  }
  const glm::vec3 fallback = cube_lookup_trilinear(cube, std::sqrt(alpha) * top_level, corrected(glm::reflect(-v, n)));
  glm::vec3 out;
  for (int k = 0; k < 3; ++k) out[k] = weight[k] > 0.0f ? sum[k] / weight[k] : fallback[k];
  return out;
}

void prefilter_ggx(ProbeCube& cube, int samples, ThreadPool* pool) {
  const int levels = static_cast<int>(cube.levels.size());
  if (levels < 2 || samples < 1) return;
  const std::vector<std::vector<glm::vec3>> chain = box_chain(cube);
  for (int m = 1; m < levels; ++m) {
    const float r = static_cast<float>(m) / static_cast<float>(levels - 1);
    const std::vector<LobeSample> lobe =
        lobe_samples(std::max(r * r, 1e-4f), samples, cube.size, static_cast<int>(chain.size()));
    const int s = cube_level_size(cube.size, m);
    std::vector<glm::vec3>& out = cube.levels[static_cast<std::size_t>(m)];
    const auto texel = [&](std::size_t i) {
      const int face = static_cast<int>(i) / (s * s), y = static_cast<int>(i) / s % s, x = static_cast<int>(i) % s;
      const glm::vec3 n = cube_texel_direction(face, x, y, s);
      glm::vec3 t, b;
      orthonormal_basis(n, t, b);
      glm::vec3 sum(0.0f);
      float weight = 0.0f;
      for (const LobeSample& ls : lobe) {
        const glm::vec3 h = ls.tangent_h.x * t + ls.tangent_h.y * b + ls.tangent_h.z * n;
        const glm::vec3 l = 2.0f * glm::dot(n, h) * h - n;
        const float nl = glm::dot(n, l);
        if (nl <= 0.0f) continue;
        sum += nl * read_chain(chain, cube.size, ls.lod, l);
        weight += nl;
      }
      out[i] = weight > 0.0f ? sum / weight : read_chain(chain, cube.size, 0.0f, n);
    };
    if (pool)
      pool->parallel_for(out.size(), texel, 16);
    else
      for (std::size_t i = 0; i < out.size(); ++i) texel(i);
  }
}

}  // namespace gi
