#include "dlm/dlm.h"

#include "core/color.h"
#include "core/stopwatch.h"
#include "raytrace/material_lookup.h"

#include <engine/directional_radiance.h>
#include <engine/finite.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>

#include "core/random.h"
#include "core/thread_pool.h"
#include "raytrace/light_falloff.h"
#include "raytrace/ray_offset.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"
#include "transport/vpl_transport.h"
#include "uv/atlas_density.h"
#include "uv/atlas_dilation.h"
#include "uv/atlas_input.h"

namespace gi {
namespace {

using Clock = std::chrono::steady_clock;

constexpr float kPi = std::numbers::pi_v<float>;
// Photons per batch (a batch is traced by one thread, its deposits merged in photon order)
// and batches per merge round (bounds the deposits held at once; progress per round).
constexpr std::uint64_t kBatchPhotons = 2048;
constexpr std::uint64_t kRoundBatches = 64;

engine::Status validate(const DlmSettings& s) {
  const auto bad = [](std::string what) { return engine::invalid_request("DLM settings: " + what); };
  if (!(s.texels_per_metre > 0.0f) || s.texels_per_metre > kMaxTexelsPerMetre)
    return bad("texels_per_metre " + std::to_string(s.texels_per_metre) + " is outside (0, 10^4]");
  if (s.directions < 8 || s.directions > 256)
    return bad("directions " + std::to_string(s.directions) + " is outside 8..256");
  if (s.photons < 1 || s.photons > 4'000'000'000ULL) return bad("photons must be in 1..4e9");
  if (!(s.splat_radius_texels >= 0.5f) || s.splat_radius_texels > 16.0f)
    return bad("splat_radius_texels must be in [0.5, 16]");
  if (!(s.glossy_roughness > 0.0f) || s.glossy_roughness > 1.0f) return bad("glossy_roughness must be in (0, 1]");
  if (!(s.glossy_roughness_min >= 0.0f) || !(s.glossy_roughness_min < s.glossy_roughness))
    return bad("glossy_roughness_min must be in [0, glossy_roughness)");
  if (s.max_bounces < 2 || s.max_bounces > 1024) return bad("max_bounces must be in 2..1024");
  if (s.area_light_samples < 1 || s.area_light_samples > 65536) return bad("area_light_samples must be in 1..65536");
  if (!(s.horizon_warp >= 1.0) || s.horizon_warp > 4.0) return bad("horizon_warp must be in [1, 4]");
  return {};
}

// Spherical Fibonacci lattice point i of n.
glm::vec3 fibonacci_direction(int i, int n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = golden * i;
  return glm::normalize(
      glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z)));
}

// A photon source: a point emitter with its total power (W, RGB) and how it is sampled.
struct Source {
  PointEmitter e;
  glm::vec3 power{0.0f};
};

// One photon leaving a source.
struct Photon {
  glm::vec3 origin;
  glm::vec3 direction;
  glm::vec3 power;
  float range_m = 0.0f;  // punctual range window applied at the first hit
};

struct SceneBounds {
  glm::vec3 centre{0.0f};
  float radius = 1.0f;
};

Photon emit(const Source& s, const SceneBounds& bounds, float share, Pcg32& rng) {
  const float u1 = rng.next_float(), u2 = rng.next_float(), u3 = rng.next_float();
  Photon p;
  p.power = s.power * share;
  const PointEmitter& e = s.e;
  switch (e.kind) {
    case PointEmitter::Kind::Punctual: {
      // Uniform over the sphere, or over the outer cone of a spot (the cone's smoothstep
      // weights the photon).
      const float cos_max = e.spot ? std::clamp(e.cos_outer, -1.0f, 1.0f) : -1.0f;
      const float cos_t = 1.0f - u1 * (1.0f - cos_max);
      const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
      const float phi = 2.0f * kPi * u2;
      glm::vec3 t, b;
      const glm::vec3 axis = e.spot ? glm::normalize(e.direction) : glm::vec3(0.0f, 0.0f, 1.0f);
      orthonormal_basis(axis, t, b);
      p.direction = glm::normalize(sin_t * std::cos(phi) * t + sin_t * std::sin(phi) * b + cos_t * axis);
      p.origin = e.position;
      if (e.spot) p.power *= spot_cone(e.direction, e.cos_outer, e.cos_inner, -p.direction);
      p.range_m = e.range_m;
      break;
    }
    case PointEmitter::Kind::Directional: {
      glm::vec3 t, b;
      const glm::vec3 d = glm::normalize(e.direction);
      orthonormal_basis(d, t, b);
      const float r = bounds.radius * std::sqrt(u1), phi = 2.0f * kPi * u2;
      p.direction = d;
      p.origin = bounds.centre - 2.0f * bounds.radius * d + r * (std::cos(phi) * t + std::sin(phi) * b);
      break;
    }
    case PointEmitter::Kind::Lambertian: {
      glm::vec3 n = glm::normalize(e.direction);
      if (e.two_sided && u3 < 0.5f) n = -n;
      p.direction = sample_cosine_hemisphere(n, u1, u2);
      p.origin = offset_ray_origin(e.position, n);
      break;
    }
  }
  return p;
}

std::vector<Source> photon_sources(const std::vector<PointEmitter>& emitters, const SceneBounds& bounds) {
  std::vector<Source> out;
  for (const PointEmitter& e : emitters) {
    Source s{e, glm::vec3(0.0f)};
    switch (e.kind) {
      case PointEmitter::Kind::Punctual: {
        const float cos_max = e.spot ? std::clamp(e.cos_outer, -1.0f, 1.0f) : -1.0f;
        s.power = e.radiant * (2.0f * kPi * (1.0f - cos_max));
        break;
      }
      case PointEmitter::Kind::Directional:
        s.power = e.radiant * (kPi * bounds.radius * bounds.radius);
        break;
      case PointEmitter::Kind::Lambertian:
        s.power = e.radiant * (e.two_sided ? 2.0f : 1.0f);
        break;
    }
    if (luminance(s.power) > 0.0f && engine::all_finite(s.power)) out.push_back(s);
  }
  return out;
}

// A photon's share of the map: one (element, bin) and its irradiance (W/m^2).
struct Deposit {
  std::uint32_t element;
  std::uint32_t bin;
  glm::vec3 irradiance;
};

}  // namespace

std::vector<glm::vec3> dlm_directions(int count) {
  std::vector<glm::vec3> out;
  for (int i = 0; i < count; ++i) out.push_back(fibonacci_direction(i, count));
  return out;
}

std::vector<glm::vec3> dlm_hemisphere_directions(int count, double horizon_warp) {
  std::vector<glm::vec3> out;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    // Uniform in z (equal areas on the hemisphere), or z^warp: denser towards the horizon.
    const double z = std::pow(1.0 - (i + 0.5) / count, horizon_warp);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    out.push_back(glm::normalize(glm::vec3(static_cast<float>(r * std::cos(golden * i)),
                                           static_cast<float>(r * std::sin(golden * i)), static_cast<float>(z))));
  }
  return out;
}

std::vector<glm::vec3> dlm_texel_directions(const Dlm& dlm, const glm::vec3& n) {
  if (!dlm.settings.tangent_frame_bins) return dlm.directions;
  glm::vec3 t, b;
  engine::directional_tangent_frame(n, t, b);  // the renderer's frame (GLSL twin), so its bins are these
  std::vector<glm::vec3> out;
  out.reserve(dlm.directions.size());
  for (const glm::vec3& d : dlm.directions) out.push_back(d.x * t + d.y * b + d.z * n);
  return out;
}

std::uint32_t dlm_bin(std::span<const glm::vec3> directions, const glm::vec3& w) {
  std::uint32_t best = 0;
  float best_dot = -2.0f;
  for (std::size_t k = 0; k < directions.size(); ++k) {
    const float d = glm::dot(w, directions[k]);
    if (d > best_dot) best_dot = d, best = static_cast<std::uint32_t>(k);
  }
  return best;
}

std::vector<float> dlm_bin_cosine_weights(std::span<const glm::vec3> directions, const glm::vec3& n, int quadrature) {
  std::vector<double> c(directions.size(), 0.0);
  const double dw = 4.0 * std::numbers::pi / quadrature;
  for (int i = 0; i < quadrature; ++i) {
    const glm::vec3 w = fibonacci_direction(i, quadrature);
    const float cos_w = glm::dot(n, w);
    if (!(cos_w > 0.0f)) continue;
    c[dlm_bin(directions, w)] += static_cast<double>(cos_w) * dw;
  }
  return std::vector<float>(c.begin(), c.end());
}

engine::Result<DlmSettings> dlm_preset(std::string_view name) {
  auto density = atlas_density_preset(name);
  if (!density)
    return engine::invalid_request("unknown DLM preset '" + std::string(name) + "' (preview, medium, high)");
  DlmSettings s;
  s.texels_per_metre = *density;
  // The photons a texel-bin receives fall with the density squared: the counts keep roughly
  // the preview's deposits per texel and bin (docs/dlm.md). 64 bins in each texel's tangent
  // frame: the corridor's grazing band +14% -> -8% at the preview (docs/dlm.md, "Tangent-frame
  // bins in the renderer"); the preview's 3-texel kernel measured better on both scenes than 2.
  // Medium and high: 1.5x a 2 M preview's deposits per texel and bin, the same kernel in texels.
  // Their earlier 6 M / 2 texels and 16 M / 2.5 texels left a third to a half of those deposits
  // per texel: the corridor's grazing band at rel RMSE 0.31 at both; 12 M and 48 M bring it to
  // 0.19 (docs/dlm.md "The medium and high presets"). The preview: 6 M, since at 2 M its
  // grazing band read 0.211 / 0.232 (seeds 1 / 2) against issue 36's 0.2, at 6 M 0.161 / 0.179;
  // the DLM bake 2.0 -> 5.9 s on glossy_room, 0.7 -> 1.9 s on the demo level (docs/dlm.md
  // "The preview's photons").
  s.directions = 64, s.tangent_frame_bins = true;
  s.splat_radius_texels = 3.0f;
  if (name == "preview") {
    s.photons = 6'000'000;
  } else if (name == "medium") {
    s.photons = 12'000'000;  // 2 M x (16 / 8)^2 x 1.5
  } else {
    s.photons = 48'000'000;  // 2 M x (32 / 8)^2 x 1.5
  }
  return s;
}

namespace {

// Per triangle of the snapshot: glossy (rougher than the settings' limit or not) and the
// folded albedo of its material.
struct TriangleMaterials {
  std::vector<std::uint8_t> glossy;
  std::vector<glm::vec3> albedo;
};

TriangleMaterials triangle_materials(const StaticBakeScene& s, const DlmSettings& settings) {
  TriangleMaterials out;
  out.glossy.assign(s.index.triangles.size(), 0);
  out.albedo.resize(s.index.triangles.size());
  std::map<std::uint32_t, std::pair<bool, glm::vec3>> by_material;
  for (std::size_t t = 0; t < s.index.triangles.size(); ++t) {
    const std::uint32_t m = s.index.triangles[t].material;
    auto it = by_material.find(m);
    if (it == by_material.end()) {
      const engine::GltfBrdf& brdf = s.scene.materials[m].brdf;
      it = by_material
               .emplace(m, std::make_pair(std::sqrt(brdf.alpha) < settings.glossy_roughness &&
                                              std::sqrt(brdf.alpha) >= settings.glossy_roughness_min,
                                          engine::gltf_hemispherical_albedo(brdf).sum()))
               .first;
    }
    out.glossy[t] = it->second.first ? 1 : 0;
    // Textured: the texture's mean over the triangle (the material lookup, material_lookup.h).
    out.albedo[t] =
        s.scene.materials[m].textured() ? gi::triangle_albedo(s.scene, s.index.triangles[t]) : it->second.second;
  }
  return out;
}

// The glossy texels of the atlas: a mask, each one's element index (-1 elsewhere) and the
// list of them in texel order.
struct GlossyTexels {
  std::vector<std::uint8_t> mask;
  std::vector<std::int32_t> element;
  std::vector<std::uint32_t> texels;
};

GlossyTexels glossy_texels_of(const StaticBakeScene& s, const std::vector<std::uint8_t>& triangle_glossy) {
  const AtlasTexels& tex = s.texels;
  const std::size_t n_texels = tex.valid.size();
  GlossyTexels g;
  g.mask.assign(n_texels, 0);
  g.element.assign(n_texels, -1);
  for (std::size_t t = 0; t < n_texels; ++t) {
    if (!tex.valid[t] || tex.mesh[t] < 0) continue;
    const std::uint32_t inst = s.static_instance[static_cast<std::size_t>(tex.mesh[t])];
    const std::uint32_t tri = s.index.instance_first[inst] + static_cast<std::uint32_t>(tex.triangle[t]);
    if (!triangle_glossy[tri]) continue;
    g.mask[t] = 1;
    g.element[t] = static_cast<std::int32_t>(g.texels.size());
    g.texels.push_back(static_cast<std::uint32_t>(t));
  }
  return g;
}

// C_k(n) per glossy texel, shared by texels of equal normals: the weights, the bins'
// directions in world space (dlm_texel_directions) and each texel's slot.
struct CosineWeights {
  std::vector<std::vector<float>> weights;
  std::vector<std::vector<glm::vec3>> directions;
  std::vector<std::uint32_t> texel_slot;
};

CosineWeights cosine_weights_of(const AtlasTexels& tex, const std::vector<std::uint32_t>& glossy_texels,
                                const Dlm& dlm) {
  std::map<std::array<float, 3>, std::uint32_t> normal_slot;
  CosineWeights out;
  out.texel_slot.resize(glossy_texels.size());
  // Tangent-frame bins have the same C_k at every normal: once, finely.
  const std::vector<float> tangent_weights =
      dlm.settings.tangent_frame_bins
          ? dlm_bin_cosine_weights(dlm.directions, glm::vec3(0.0f, 0.0f, 1.0f), kDlmTangentQuadrature)
          : std::vector<float>{};
  for (std::size_t i = 0; i < glossy_texels.size(); ++i) {
    const glm::vec3 n = tex.normal[glossy_texels[i]];
    const std::array<float, 3> key{n.x, n.y, n.z};
    auto it = normal_slot.find(key);
    if (it == normal_slot.end()) {
      it = normal_slot.emplace(key, static_cast<std::uint32_t>(out.weights.size())).first;
      out.directions.push_back(dlm_texel_directions(dlm, n));
      out.weights.push_back(dlm.settings.tangent_frame_bins ? tangent_weights
                                                            : dlm_bin_cosine_weights(out.directions.back(), n));
    }
    out.texel_slot[i] = it->second;
  }
  return out;
}

// The sphere around every triangle of the snapshot (directional photons start outside it).
SceneBounds scene_bounds(const std::vector<ShadingTriangle>& triangles) {
  SceneBounds bounds;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const ShadingTriangle& t : triangles)
    for (const glm::vec3& p : {t.p0, t.p0 + t.e1, t.p0 + t.e2}) lo = glm::min(lo, p), hi = glm::max(hi, p);
  bounds.centre = 0.5f * (lo + hi);
  bounds.radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  return bounds;
}

// The tent kernel of the photon splats over the atlas's glossy texels.
struct SplatKernel {
  const Dlm& dlm;
  const AtlasTexels& tex;
  const GlossyTexels& glossy;
  const CosineWeights& cosine;  // each texel's bins' directions
  float radius;
  int W, H;

  float weight(float dx, float dy) const {
    return std::max(0.0f, 1.0f - std::fabs(dx) / radius) * std::max(0.0f, 1.0f - std::fabs(dy) / radius);
  }
  // Texel-space position of barycentrics `bc` on triangle `prim` of atlas mesh `c` (texel
  // centres at integers).
  glm::vec2 texel_point(std::uint32_t c, std::uint32_t prim, glm::vec2 bc) const {
    const AtlasMeshUv& mesh = dlm.layout.meshes[c];
    const glm::vec2 uv = (1.0f - bc.x - bc.y) * mesh.uv1[mesh.indices[3 * prim]] +
                         bc.x * mesh.uv1[mesh.indices[3 * prim + 1]] + bc.y * mesh.uv1[mesh.indices[3 * prim + 2]];
    return glm::vec2(uv.x * static_cast<float>(W) - 0.5f, uv.y * static_cast<float>(H) - 0.5f);
  }
  // Calls fn(texel, weight) for the glossy texels of `chart` the kernel at texel-space point q reaches.
  template <class Fn>
  void for_kernel(glm::vec2 q, std::int32_t chart, Fn&& fn) const {
    const int x0 = std::max(0, static_cast<int>(std::ceil(q.x - radius))),
              x1 = std::min(W - 1, static_cast<int>(std::floor(q.x + radius)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(q.y - radius))),
              y1 = std::min(H - 1, static_cast<int>(std::floor(q.y + radius)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const std::size_t t = tex.index(x, y);
        if (!glossy.mask[t] || tex.chart[t] != chart) continue;
        const float w = weight(static_cast<float>(x) - q.x, static_cast<float>(y) - q.y);
        if (w > 0.0f) fn(t, w);
      }
  }
  // Splats a photon arriving along -`w_in` at barycentrics `bc` of triangle `prim` of caster
  // instance `c` (= atlas mesh c) into the glossy texels of its chart: K x power, divided by
  // the normalizer once everything is summed.
  bool splat(std::uint32_t c, std::uint32_t prim, glm::vec2 bc, const glm::vec3& w_in, const glm::vec3& power,
             std::vector<Deposit>& out) const {
    const std::size_t first = out.size();
    for_kernel(texel_point(c, prim, bc), static_cast<std::int32_t>(dlm.layout.meshes[c].triangle_chart[prim]),
               [&](std::size_t t, float w) {
                 const auto e = static_cast<std::uint32_t>(glossy.element[t]);
                 out.push_back({e, dlm_bin(cosine.directions[cosine.texel_slot[e]], w_in), w * power});
               });
    return out.size() > first;
  }
};

// Kernel density estimation: E_t = sum_i Phi_i K(x_i - x_t) / integral of K(x - x_t) dA
// over the glossy surface of t's chart. The normalizer is integrated over every glossy
// triangle with kSub x kSub points per texel (each standing for its share of the
// triangle's world area), so texels at chart borders (partly covered, or covered only
// conservatively) estimate the same density as inner ones.
std::vector<double> kernel_normalizers(const StaticBakeScene& s, const SplatKernel& kernel,
                                       const std::vector<std::uint8_t>& triangle_glossy) {
  constexpr int kSub = 4;
  const Dlm& dlm = kernel.dlm;
  std::vector<double> normalizer(kernel.glossy.texels.size(), 0.0);
  for (std::uint32_t c = 0; c < dlm.layout.meshes.size(); ++c) {
    const AtlasMeshUv& mesh = dlm.layout.meshes[c];
    const std::uint32_t first = s.index.instance_first[s.static_instance[c]];
    for (std::uint32_t prim = 0; prim < mesh.indices.size() / 3; ++prim) {
      const std::uint32_t tri = first + prim;
      if (!triangle_glossy[tri]) continue;
      const glm::vec2 a = kernel.texel_point(c, prim, {0.0f, 0.0f}), b = kernel.texel_point(c, prim, {1.0f, 0.0f}),
                      d = kernel.texel_point(c, prim, {0.0f, 1.0f});
      const glm::vec2 e1 = b - a, e2 = d - a;
      const float det = e1.x * e2.y - e1.y * e2.x;
      if (!(std::fabs(det) > 1e-12f)) continue;
      const double area_per_point = static_cast<double>(s.index.triangles[tri].area_m2) /
                                    (0.5 * std::fabs(static_cast<double>(det)) * kSub * kSub);
      const auto chart = static_cast<std::int32_t>(mesh.triangle_chart[prim]);
      const glm::vec2 lo = glm::min(a, glm::min(b, d)), hi = glm::max(a, glm::max(b, d));
      const auto m0 = static_cast<int>(std::floor((lo.x + 0.5f) * kSub)),
                 m1 = static_cast<int>(std::ceil((hi.x + 0.5f) * kSub));
      const auto n0 = static_cast<int>(std::floor((lo.y + 0.5f) * kSub)),
                 n1 = static_cast<int>(std::ceil((hi.y + 0.5f) * kSub));
      for (int ny = n0; ny <= n1; ++ny)
        for (int mx = m0; mx <= m1; ++mx) {
          // Shifted off the sub-grid's centres so that no point lies exactly on an edge two
          // triangles share (the diagonal of a texel-aligned quad), which would count it twice.
          const glm::vec2 q((static_cast<float>(mx) + 0.5123f) / kSub - 0.5f,
                            (static_cast<float>(ny) + 0.5371f) / kSub - 0.5f);
          const glm::vec2 r = q - a;
          const float u = (r.x * e2.y - r.y * e2.x) / det, v = (e1.x * r.y - e1.y * r.x) / det;
          if (u < 0.0f || v < 0.0f || u + v > 1.0f) continue;
          kernel.for_kernel(q, chart, [&](std::size_t t, float w) {
            normalizer[static_cast<std::size_t>(kernel.glossy.element[t])] += static_cast<double>(w) * area_per_point;
          });
        }
    }
  }
  return normalizer;
}

// The photon sources with the cumulative luminance of their powers (for picking one).
struct SourcePicker {
  std::vector<Source> sources;
  std::vector<double> cdf;
  double total = 0.0;
};

SourcePicker source_picker(std::vector<Source> sources) {
  SourcePicker out;
  out.sources = std::move(sources);
  for (const Source& src : out.sources) out.cdf.push_back(out.total += static_cast<double>(luminance(src.power)));
  return out;
}

struct BatchResult {
  std::vector<Deposit> deposits;
  std::uint64_t rays = 0, hits = 0, lost = 0;
};

// Traces the photons of batch `batch` through the scene, splatting every hit on a glossy
// front face after the first bounce; Russian roulette on the folded albedo ends a path.
void trace_batch(const StaticBakeScene& s, const DlmSettings& settings, const TriangleMaterials& materials,
                 const SourcePicker& picker, const SceneBounds& bounds, const SplatKernel& kernel, std::uint64_t batch,
                 BatchResult& r) {
  const std::uint64_t begin = batch * kBatchPhotons, end = std::min(settings.photons, begin + kBatchPhotons);
  const double total = picker.total;
  const float share = static_cast<float>(total / static_cast<double>(settings.photons));
  for (std::uint64_t i = begin; i < end; ++i) {
    Pcg32 rng = Pcg32::for_item(settings.seed, i);
    const double u = static_cast<double>(rng.next_float()) * total;
    const auto pick =
        static_cast<std::size_t>(std::upper_bound(picker.cdf.begin(), picker.cdf.end(), u) - picker.cdf.begin());
    const Source& src = picker.sources[std::min(pick, picker.sources.size() - 1)];
    // Power / pick probability / photons: the source's RGB power over its luminance x share.
    Photon p = emit(src, bounds, share / luminance(src.power), rng);
    for (int bounce = 0; bounce < settings.max_bounces; ++bounce) {
      const float u1 = rng.next_float(), u2 = rng.next_float(), u_rr = rng.next_float();
      ++r.rays;
      const Hit hit = s.caster->intersect(Ray{p.origin, 0.0f, p.direction});
      if (!hit.valid()) break;
      glm::vec3 ng = glm::normalize(hit.geometric_normal);
      const std::uint32_t tri = s.triangle_of(hit);
      const ShadingTriangle& st = s.index.triangles[tri];
      const bool front = glm::dot(ng, p.direction) < 0.0f;
      if (!front) {
        if (!s.scene.materials[st.material].double_sided) break;
        ng = -ng;
      }
      if (bounce == 0 && p.range_m > 0.0f) p.power *= range_window(hit.t, p.range_m);
      if (bounce >= 1 && front && materials.glossy[tri]) {
        ++r.hits;
        if (!kernel.splat(hit.instance, hit.primitive, hit.barycentric, -p.direction, p.power, r.deposits)) ++r.lost;
      }
      const glm::vec3 albedo = materials.albedo[tri];
      const float q = std::min(1.0f, max_component(albedo));
      if (!(u_rr < q)) break;
      p.power *= albedo / q;
      const glm::vec3 position = st.p0 + hit.barycentric.x * st.e1 + hit.barycentric.y * st.e2;
      p.origin = offset_ray_origin(position, ng);
      p.direction = sample_cosine_hemisphere(ng, u1, u2);
    }
  }
}

// Traces the photons in rounds of batches, their deposits summed in photon order (batch
// order, then within) into the irradiance per [bin][element][channel]; counts into `stats`.
engine::Result<std::vector<double>> trace_photons(const StaticBakeScene& s, const DlmSettings& settings,
                                                  const TriangleMaterials& materials, const SourcePicker& picker,
                                                  const SceneBounds& bounds, const SplatKernel& kernel,
                                                  DlmStats& stats) {
  const std::size_t n_elements = kernel.glossy.texels.size();
  std::vector<double> irradiance(kernel.dlm.directions.size() * n_elements * 3, 0.0);  // [bin][element][ch]
  ThreadPool pool(settings.threads);
  const std::uint64_t batches = picker.sources.empty() ? 0 : (settings.photons + kBatchPhotons - 1) / kBatchPhotons;
  for (std::uint64_t round = 0; round < batches; round += kRoundBatches) {
    const std::uint64_t count = std::min(kRoundBatches, batches - round);
    std::vector<BatchResult> results(count);
    pool.parallel_for(count, [&](std::size_t b) {
      trace_batch(s, settings, materials, picker, bounds, kernel, round + b, results[b]);
    });
    for (const BatchResult& r : results) {
      stats.rays += r.rays;
      stats.deposits += r.hits;
      stats.lost_deposits += r.lost;
      for (const Deposit& d : r.deposits) {
        double* e = &irradiance[(d.bin * n_elements + d.element) * 3];
        e[0] += static_cast<double>(d.irradiance.x), e[1] += static_cast<double>(d.irradiance.y),
            e[2] += static_cast<double>(d.irradiance.z);
      }
    }
    if (settings.progress &&
        !settings.progress(0.95 * static_cast<double>(round + count) / static_cast<double>(batches)))
      return engine::cancelled_error("DLM bake");
  }
  return irradiance;
}

// Mean radiance per bin, then every bin's map dilated into the gutter next to its chart
// (only texels no chart covers: another chart's texels keep their own data or none).
void resolve_bins(const AtlasTexels& tex, const GlossyTexels& glossy, const CosineWeights& cosine,
                  const std::vector<double>& normalizer, const std::vector<double>& irradiance, Dlm& dlm) {
  const std::size_t n_bins = dlm.directions.size(), n_texels = tex.valid.size();
  const std::vector<std::uint32_t>& glossy_texels = glossy.texels;
  const int rings = std::max(1, dlm.layout.padding_texels / 2);
  std::vector<glm::vec3> image(n_texels);
  std::vector<std::uint8_t> filled;
  for (std::size_t k = 0; k < n_bins; ++k) {
    std::fill(image.begin(), image.end(), glm::vec3(0.0f));
    for (std::size_t i = 0; i < glossy_texels.size(); ++i) {
      const float c = cosine.weights[cosine.texel_slot[i]][k];
      if (!(c > 0.0f)) continue;
      if (!(normalizer[i] > 0.0)) continue;
      const double* e = &irradiance[(k * glossy_texels.size() + i) * 3];
      image[glossy_texels[i]] = glm::vec3(glm::dvec3(e[0], e[1], e[2]) / (static_cast<double>(c) * normalizer[i]));
    }
    filled = dilate<glm::vec3>(image, dlm.width, dlm.height, glossy.mask, rings);
    if (k == 0) {  // the grown mask depends on the glossy texels only: the same for every bin
      for (std::size_t t = 0; t < n_texels; ++t)
        if (glossy.mask[t] || (filled[t] && !tex.valid[t])) dlm.texels.push_back(static_cast<std::uint32_t>(t));
      dlm.radiance.resize(n_bins * dlm.texels.size() * 3);
    }
    for (std::size_t i = 0; i < dlm.texels.size(); ++i)
      std::memcpy(&dlm.radiance[(k * dlm.texels.size() + i) * 3], &image[dlm.texels[i]], sizeof(glm::vec3));
  }
}

}  // namespace

engine::Result<Dlm> bake_dlm(const BakeInput& input, const DlmSettings& settings) {
  if (auto ok = validate(settings); !ok) return ok.error();
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  const auto t_start = Clock::now();
  auto layout = static_world_layout(input, settings.texels_per_metre);
  if (!layout) return layout.error();
  auto prepared = prepare_static_scene(input, *layout, BakeLights::Static);
  if (!prepared) return prepared.error();
  const StaticBakeScene& s = *prepared;
  const AtlasTexels& tex = s.texels;

  Dlm dlm;
  dlm.settings = settings;
  dlm.layout = std::move(layout).value();
  dlm.width = dlm.layout.width;
  dlm.height = dlm.layout.height;
  dlm.directions = settings.tangent_frame_bins ? dlm_hemisphere_directions(settings.directions, settings.horizon_warp)
                                               : dlm_directions(settings.directions);

  const TriangleMaterials materials = triangle_materials(s, settings);
  const GlossyTexels glossy = glossy_texels_of(s, materials.glossy);
  const std::vector<std::uint32_t>& glossy_texels = glossy.texels;
  dlm.stats.glossy_texels = glossy_texels.size();
  if (glossy_texels.empty()) {
    dlm.stats.total_seconds = seconds_since(t_start);
    return dlm;
  }
  const CosineWeights cosine = cosine_weights_of(tex, glossy_texels, dlm);

  const SceneBounds bounds = scene_bounds(s.index.triangles);
  const SourcePicker picker = source_picker(
      photon_sources(point_emitters(s.scene, s.index, settings.area_light_samples, settings.seed), bounds));
  dlm.stats.emitted_watts = picker.total;

  const SplatKernel kernel{dlm, tex, glossy, cosine, settings.splat_radius_texels, dlm.width, dlm.height};
  const std::vector<double> normalizer = kernel_normalizers(s, kernel, materials.glossy);

  const auto t_trace = Clock::now();
  auto irradiance = trace_photons(s, settings, materials, picker, bounds, kernel, dlm.stats);
  if (!irradiance) return irradiance.error();
  dlm.stats.photons = picker.sources.empty() ? 0 : settings.photons;
  dlm.stats.trace_seconds = seconds_since(t_trace);

  resolve_bins(tex, glossy, cosine, normalizer, *irradiance, dlm);
  if (settings.progress && !settings.progress(1.0)) return engine::cancelled_error("DLM bake");
  dlm.stats.total_seconds = seconds_since(t_start);
  return dlm;
}

}  // namespace gi
