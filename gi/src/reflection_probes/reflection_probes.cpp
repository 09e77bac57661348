#include "reflection_probes/reflection_probes.h"

#include <engine/gltf_brdf.h>
#include <engine/sky.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include "core/stopwatch.h"
#include "core/thread_pool.h"
#include "raytrace/material_lookup.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"

namespace gi {

namespace {

// What one capture reads: the static world, its atlas and the static lights drawn live.
struct CaptureScene {
  const StaticBakeScene& s;
  const ProbeAtlas& atlas;
  std::vector<PointEmitter> live;  ///< The static lights the atlas does not hold.
  glm::vec3 sky_uniform{0.0f};
  engine::SkyGradient sky_gradient;
  float texel_angle = 0.0f;  ///< A level-0 texel's width in radians (the ray cone's spread).
};

// The atlas's irradiance at a hit, bilinear at its uv1 (the gutters are dilated).
glm::vec3 atlas_irradiance(const ProbeAtlas& a, const Hit& h) {
  const AtlasMeshUv& m = a.layout->meshes[h.instance];
  const std::uint32_t* idx = &m.indices[3u * static_cast<std::size_t>(h.primitive)];
  const glm::vec2 uv = (1.0f - h.barycentric.x - h.barycentric.y) * m.uv1[idx[0]] + h.barycentric.x * m.uv1[idx[1]] +
                       h.barycentric.y * m.uv1[idx[2]];
  const float fx = uv.x * static_cast<float>(a.width) - 0.5f, fy = uv.y * static_cast<float>(a.height) - 0.5f;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0);
  const auto at = [&](int x, int y) {
    x = std::clamp(x, 0, a.width - 1);
    y = std::clamp(y, 0, a.height - 1);
    return a.irradiance[static_cast<std::size_t>(y) * static_cast<std::size_t>(a.width) + static_cast<std::size_t>(x)];
  };
  return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), tx), glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), tx), ty);
}

// The static lights' direct light reflected towards wo through the glTF BRDF, shadowed.
glm::vec3 live_direct(const CaptureScene& c, const glm::vec3& p, const glm::vec3& n, const glm::vec3& wo,
                      const engine::GltfBrdf& brdf, std::uint32_t& rays) {
  glm::vec3 sum(0.0f);
  for (const PointEmitter& e : c.live) {
    const glm::vec3 l =
        e.kind == PointEmitter::Kind::Directional ? -glm::normalize(e.direction) : glm::normalize(e.position - p);
    const float cos_l = glm::dot(n, l);
    if (!(cos_l > 1e-4f)) continue;
    const glm::vec3 irradiance = emitter_irradiance(e, p, n, 0.0f);
    if (irradiance == glm::vec3(0.0f)) continue;
    ++rays;
    if (!emitter_visible(*c.s.caster, e, p, n)) continue;
    sum += irradiance * engine::gltf_eval_cos(brdf, n, wo, l).sum() / cos_l;
  }
  return sum;
}

// Radiance arriving at `origin` along unit `d`: what the renderer draws where the ray lands;
// `distance` the distance to that surface (unchanged when the ray leaves the scene).
glm::vec3 capture_radiance(const CaptureScene& c, const glm::vec3& origin, const glm::vec3& d, std::uint32_t& rays,
                           float& distance) {
  ++rays;
  const Hit h = c.s.caster->intersect(Ray{origin, 0.0f, d});
  if (!h.valid()) return engine::sky_radiance(c.sky_uniform, c.sky_gradient, d);
  distance = h.t;
  const ShadingTriangle& tri = c.s.index.triangles[c.s.triangle_of(h)];
  const bool front = glm::dot(d, tri.face_normal) < 0.0f;
  if (!front && !c.s.scene.materials[tri.material].double_sided) return glm::vec3(0.0f);
  const glm::vec2 bc = h.barycentric;
  glm::vec3 n = glm::normalize((1.0f - bc.x - bc.y) * tri.n0 + bc.x * tri.n1 + bc.y * tri.n2);
  if (!front) n = -n;
  const glm::vec3 wo = -d;
  const float n_dot_v = std::max(glm::dot(n, wo), 1e-4f);
  const float footprint = h.t * c.texel_angle;
  const glm::vec3 p = origin + h.t * d;
  const engine::GltfBrdf brdf = material_brdf_at(c.s.scene, tri, bc, footprint);
  const glm::vec3 e = atlas_irradiance(c.atlas, h);
  glm::vec3 l = emission_at(c.s.scene, tri, bc, footprint);
  l += e / std::numbers::pi_v<float> * engine::gltf_directional_albedo(brdf, n_dot_v).sum();
  l += live_direct(c, p, n, wo, brdf, rays);
  return l;
}

// Level 0 of one probe: the mean of supersample^2 stratified rays per texel. Its distances, at
// kProbeDistanceScale x level 0's face size: per quarter of a level-0 texel, the mean distance
// of the texel's rays through that quarter that met a surface (kProbeFarDistance when none
// did); a quarter no ray passes through (supersample 1) takes the texel's mean.
// `pool` null: on the calling thread.
void capture(const CaptureScene& c, const glm::vec3& centre, int supersample, ProbeCube& cube, ThreadPool* pool,
             std::vector<std::uint32_t>& rays) {
  static_assert(kProbeDistanceScale == 2, "the capture splits each texel's rays into 2 x 2 quarters");
  const int s = cube.size, ds = kProbeDistanceScale * s;
  std::vector<glm::vec3>& out = cube.levels[0];
  rays.assign(out.size(), 0);
  cube.distance_size = ds;
  cube.distance.assign(static_cast<std::size_t>(6 * ds * ds), kProbeFarDistance);
  const auto texel = [&](std::size_t i) {
    const int face = static_cast<int>(i) / (s * s), y = static_cast<int>(i) / s % s, x = static_cast<int>(i) % s;
    glm::vec3 sum(0.0f);
    std::array<float, 5> distance_sum{};  // the four quarters, then the whole texel
    std::array<int, 5> hits{}, through{};
    for (int j = 0; j < supersample; ++j)
      for (int k = 0; k < supersample; ++k) {
        const float u = (static_cast<float>(x) + (static_cast<float>(k) + 0.5f) / static_cast<float>(supersample)) /
                            static_cast<float>(s) * 2.0f -
                        1.0f;
        const float v = (static_cast<float>(y) + (static_cast<float>(j) + 0.5f) / static_cast<float>(supersample)) /
                            static_cast<float>(s) * 2.0f -
                        1.0f;
        float distance = -1.0f;
        sum += capture_radiance(c, centre, cube_direction(face, u, v), rays[i], distance);
        const auto quarter = static_cast<std::size_t>(2 * (2 * j / supersample) + 2 * k / supersample);
        ++through[quarter];
        if (distance < 0.0f) continue;
        distance_sum[quarter] += distance, ++hits[quarter];
        distance_sum[4] += distance, ++hits[4];
      }
    out[i] = sum / static_cast<float>(supersample * supersample);
    for (int q = 0; q < 4; ++q) {
      const auto from = static_cast<std::size_t>(through[static_cast<std::size_t>(q)] > 0 ? q : 4);
      if (hits[from] > 0)
        cube.distance[cube_texel_index(face, 2 * x + q % 2, 2 * y + q / 2, ds)] =
            distance_sum[from] / static_cast<float>(hits[from]);
    }
  };
  if (pool)
    pool->parallel_for(out.size(), texel, 16);
  else
    for (std::size_t i = 0; i < out.size(); ++i) texel(i);
}

std::string check_atlas(const BakeInput& input, const ProbeAtlas& a) {
  if (!a.layout) return "no light atlas to read the static surfaces' light from";
  if (a.width != a.layout->width || a.height != a.layout->height ||
      a.irradiance.size() != static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height))
    return "the light atlas's irradiance does not match its layout's size";
  const auto statics = std::count_if(input.instances.begin(), input.instances.end(),
                                     [](const BakeInstance& i) { return i.mobility == BakeMobility::Static; });
  if (a.layout->meshes.size() != static_cast<std::size_t>(statics))
    return "the light atlas's layout has " + std::to_string(a.layout->meshes.size()) + " meshes for " +
           std::to_string(statics) + " static instances";
  return {};
}

struct PreparedCapture {
  StaticBakeScene scene;
  std::vector<PointEmitter> live;
};

engine::Result<PreparedCapture> prepare_capture(const BakeInput& input, const ProbeAtlas& atlas,
                                                const ReflectionProbeSettings& settings) {
  if (std::string problem = check_reflection_probe_settings(settings); !problem.empty())
    return engine::Error{.message = "reflection probes: " + problem, .kind = engine::ErrorKind::Invalid};
  if (std::string problem = check_atlas(input, atlas); !problem.empty())
    return engine::Error{.message = "reflection probes: " + problem, .kind = engine::ErrorKind::Invalid};
  auto s = prepare_static_scene(input, *atlas.layout, BakeLights::Static);
  if (!s) return s.error();
  PreparedCapture p{std::move(s).value(), {}};
  if (!atlas.holds_static_lights)
    p.live = light_point_emitters(p.scene.scene.lights, settings.area_light_samples, settings.seed);
  return p;
}

CaptureScene capture_scene(const PreparedCapture& p, const BakeInput& input, const ProbeAtlas& atlas,
                           const ReflectionProbeSettings& settings) {
  return CaptureScene{p.scene,
                      atlas,
                      p.live,
                      input.environment.sky_radiance,
                      input.environment.sky_gradient,
                      2.0f / static_cast<float>(settings.resolution)};
}

// Captures and prefilters probe i of `set`; adds its rays.
void bake_probe(const CaptureScene& c, ReflectionProbeSet& set, std::size_t i, ThreadPool& pool) {
  const ReflectionProbeSettings& st = set.settings;
  ProbeCube cube = make_probe_cube(st.resolution, full_mip_count(st.resolution));
  std::vector<std::uint32_t> rays;
  auto t0 = std::chrono::steady_clock::now();
  capture(c, set.probes[i].centre, st.supersample, cube, &pool, rays);
  set.stats.capture_seconds += seconds_since(t0);
  set.stats.rays += std::accumulate(rays.begin(), rays.end(), std::uint64_t{0});
  t0 = std::chrono::steady_clock::now();
  prefilter_ggx(cube, st.prefilter_samples, &pool);
  set.stats.prefilter_seconds += seconds_since(t0);
  set.cubes[i] = std::move(cube);
}

// The bounds of the static instances' triangles.
void static_bounds(const StaticBakeScene& s, glm::vec3& lo, glm::vec3& hi) {
  lo = glm::vec3(std::numeric_limits<float>::infinity());
  hi = -lo;
  for (std::uint32_t inst : s.static_instance) {
    const auto [first, end] = instance_triangles(s.index, inst);
    for (std::uint32_t t = first; t < end; ++t) {
      const ShadingTriangle& tri = s.index.triangles[t];
      for (const glm::vec3& q : {tri.p0, tri.p0 + tri.e1, tri.p0 + tri.e2}) {
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
      }
    }
  }
}

}  // namespace

engine::Result<ReflectionProbeSettings> reflection_probe_preset(std::string_view name) {
  ReflectionProbeSettings s;
  if (name == "preview")
    s.resolution = 16;
  else if (name == "medium")
    s.resolution = 32;
  else if (name == "high")
    s.resolution = 64;
  else
    return engine::Error{
        .message = "unknown reflection-probe preset '" + std::string(name) + "' (preview, medium, high)",
        .kind = engine::ErrorKind::Invalid};
  return s;
}

std::string check_reflection_probe_settings(const ReflectionProbeSettings& s) {
  if (s.resolution < 4 || s.resolution > 512 || !std::has_single_bit(static_cast<unsigned>(s.resolution)))
    return "resolution " + std::to_string(s.resolution) + " is not a power of two in 4..512";
  if (s.supersample < 1 || s.supersample > 8) return "supersample must be in 1..8";
  if (s.prefilter_samples < 1 || s.prefilter_samples > 65536) return "prefilter_samples must be in 1..65536";
  if (!(s.max_roughness >= 0.0f && s.max_roughness <= 1.0f)) return "max_roughness must be in [0, 1]";
  if (s.area_light_samples < 1) return "area_light_samples must be >= 1";
  const ProbePlacementSettings& p = s.placement;
  if (!(p.cell_m > 0.0f) || !std::isfinite(p.cell_m)) return "placement cell_m must be positive";
  if (!(p.spread_m >= 0.0f) || !(p.min_box_m >= 0.0f) || p.max_probes < 1 || p.max_probes > 256)
    return "placement spread_m, min_box_m >= 0 and max_probes in 1..256";
  if (!(p.capture_height >= 0.0f) || !std::isfinite(p.capture_height)) return "placement capture_height must be >= 0";
  if (!(p.second_view_height >= 0.0f) || !std::isfinite(p.second_view_height) || !(p.receiver_step_m > 0.0f) ||
      std::isnan(p.second_view_min_share))
    return "placement second_view_height must be >= 0, receiver_step_m > 0 and second_view_min_share a number";
  return {};
}

engine::Result<ReflectionProbeSet> bake_reflection_probes(const BakeInput& input, const ProbeAtlas& atlas,
                                                          const ReflectionProbeSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  auto prepared = prepare_capture(input, atlas, settings);
  if (!prepared) return prepared.error();
  ReflectionProbeSet set;
  set.settings = settings;
  glm::vec3 lo, hi;
  static_bounds(prepared->scene, lo, hi);
  auto t0 = std::chrono::steady_clock::now();
  set.probes = place_probes(*prepared->scene.caster, lo, hi, settings.placement);
  set.stats.place_seconds = seconds_since(t0);
  set.cubes.resize(set.probes.size());
  ThreadPool pool(settings.threads);
  const CaptureScene c = capture_scene(*prepared, input, atlas, settings);
  for (std::size_t i = 0; i < set.probes.size(); ++i) bake_probe(c, set, i, pool);
  set.stats.total_seconds = seconds_since(start);
  return set;
}

engine::Result<std::vector<std::size_t>> rebake_probes_touching(const BakeInput& input, const ProbeAtlas& atlas,
                                                                ReflectionProbeSet& set, const glm::vec3& changed_min,
                                                                const glm::vec3& changed_max) {
  auto prepared = prepare_capture(input, atlas, set.settings);
  if (!prepared) return prepared.error();
  std::vector<std::size_t> redone;
  ThreadPool pool(set.settings.threads);
  const CaptureScene c = capture_scene(*prepared, input, atlas, set.settings);
  for (std::size_t i = 0; i < set.probes.size(); ++i) {
    const ProbeVolume& v = set.probes[i];
    if (glm::any(glm::lessThan(v.box_max, changed_min)) || glm::any(glm::greaterThan(v.box_min, changed_max))) continue;
    bake_probe(c, set, i, pool);
    redone.push_back(i);
  }
  return redone;
}

float probe_visible_blend_weight(const ProbeVolume& v, const ProbeCube& cube, const glm::vec3& p) {
  const float w = probe_blend_weight(v, p, kProbeBoxMarginM);
  return w > 0.0f ? w * probe_visibility_weight(cube, v.centre, p) : 0.0f;
}

bool blended_probe_lobe(std::span<const ProbeVolume> probes, std::span<const ProbeCube> cubes,
                        const engine::GltfBrdf& brdf, const glm::vec3& p, const glm::vec3& n, const glm::vec3& v,
                        int samples, glm::vec3& out, bool visibility) {
  glm::vec3 sum(0.0f);
  float weight = 0.0f;
  for (std::size_t i = 0; i < probes.size() && i < cubes.size(); ++i) {
    const ProbeVolume& pv = probes[i];
    const float w =
        visibility ? probe_visible_blend_weight(pv, cubes[i], p) : probe_blend_weight(pv, p, kProbeBoxMarginM);
    if (!(w > 0.0f)) continue;
    sum += w * probe_lobe_radiance(cubes[i], brdf, p, n, v, samples, pv.centre, pv.box_min, pv.box_max, false);
    weight += w;
  }
  if (!(weight > 0.0f)) return false;
  out = sum / weight;
  return true;
}

struct ProbeCapturer::Impl {
  PreparedCapture prepared;
  ReflectionProbeSettings settings;
  ProbeAtlas atlas;
  glm::vec3 sky_uniform{0.0f};
  engine::SkyGradient sky_gradient;
};

ProbeCapturer::ProbeCapturer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ProbeCapturer::ProbeCapturer(ProbeCapturer&&) noexcept = default;
ProbeCapturer& ProbeCapturer::operator=(ProbeCapturer&&) noexcept = default;
ProbeCapturer::~ProbeCapturer() = default;

engine::Result<ProbeCapturer> ProbeCapturer::make(const BakeInput& input, const ProbeAtlas& atlas,
                                                  const ReflectionProbeSettings& settings) {
  auto prepared = prepare_capture(input, atlas, settings);
  if (!prepared) return prepared.error();
  auto impl = std::make_unique<Impl>(Impl{std::move(prepared).value(), settings, atlas, input.environment.sky_radiance,
                                          input.environment.sky_gradient});
  return ProbeCapturer(std::move(impl));
}

ProbeCube ProbeCapturer::bake_at(const glm::vec3& centre) const {
  const CaptureScene c{impl_->prepared.scene, impl_->atlas,
                       impl_->prepared.live,  impl_->sky_uniform,
                       impl_->sky_gradient,   2.0f / static_cast<float>(impl_->settings.resolution)};
  ProbeCube cube = make_probe_cube(impl_->settings.resolution, full_mip_count(impl_->settings.resolution));
  std::vector<std::uint32_t> rays;
  capture(c, centre, impl_->settings.supersample, cube, nullptr, rays);
  prefilter_ggx(cube, impl_->settings.prefilter_samples, nullptr);
  return cube;
}

glm::vec3 ProbeCapturer::radiance(const glm::vec3& origin, const glm::vec3& d, float* distance) const {
  const CaptureScene c{impl_->prepared.scene, impl_->atlas,
                       impl_->prepared.live,  impl_->sky_uniform,
                       impl_->sky_gradient,   2.0f / static_cast<float>(impl_->settings.resolution)};
  std::uint32_t rays = 0;
  float t = -1.0f;
  const glm::vec3 l = capture_radiance(c, origin, d, rays, t);
  if (distance) *distance = t;
  return l;
}

}  // namespace gi
