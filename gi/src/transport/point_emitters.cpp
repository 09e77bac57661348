#include "transport/point_emitters.h"

#include "raytrace/material_lookup.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

#include "core/random.h"
#include "core/thread_pool.h"
#include "raytrace/light_falloff.h"
#include "raytrace/ray_offset.h"

namespace gi {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Jittered points of a side x side grid over the unit square, mapped by `place`.
template <typename Place>
void stratified(int side, Pcg32& rng, Place place) {
  for (int a = 0; a < side; ++a)
    for (int b = 0; b < side; ++b) {
      const float u = (static_cast<float>(a) + rng.next_float()) / static_cast<float>(side);
      const float v = (static_cast<float>(b) + rng.next_float()) / static_cast<float>(side);
      place(u, v);
    }
}

}  // namespace

constexpr float kAreaSampleLift = 1e-3f;  // metres, light_point_emitters

std::vector<PointEmitter> light_point_emitters(std::span<const ReferenceLight> lights, int area_samples,
                                               std::uint64_t seed, const std::vector<bool>* skip) {
  const int side = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(std::max(1, area_samples))))));
  const auto strata = static_cast<float>(side * side);
  std::vector<PointEmitter> out;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    if (skip && i < skip->size() && (*skip)[i]) continue;
    const ReferenceLight& l = lights[i];
    PointEmitter e;
    e.position = l.position;
    e.direction = l.direction;
    e.radiant = l.radiant;
    e.range_m = l.range_m;
    switch (l.type) {
      case ReferenceLight::Type::Point:
        out.push_back(e);
        break;
      case ReferenceLight::Type::Spot:
        e.spot = true;
        e.cos_outer = l.cos_outer;
        e.cos_inner = l.cos_inner;
        out.push_back(e);
        break;
      case ReferenceLight::Type::Directional:
        e.kind = PointEmitter::Kind::Directional;
        out.push_back(e);
        break;
      case ReferenceLight::Type::Area: {
        const float area = 4.0f * glm::length(l.half_x) * glm::length(l.half_y);
        if (!(area > 0.0f)) break;
        Pcg32 rng = Pcg32::for_item(seed, 0x4c000000ULL + i);
        stratified(side, rng, [&](float u, float v) {
          PointEmitter p;
          p.kind = PointEmitter::Kind::Lambertian;
          // 1 mm in front of the light's plane: a panel drawn for the light (its emissive
          // proxy, just in front of the plane so the light is not inside it) must not shadow
          // the light's own points.
          p.position =
              l.position + (2.0f * u - 1.0f) * l.half_x + (2.0f * v - 1.0f) * l.half_y + kAreaSampleLift * l.direction;
          p.direction = l.direction;
          p.radiant = kPi * l.radiant * area / strata;
          p.area_m2 = area / strata;
          out.push_back(p);
        });
        break;
      }
    }
  }
  return out;
}

std::vector<PointEmitter> point_emitters(const ReferenceScene& scene, const ReferenceSceneIndex& index,
                                         int area_samples, std::uint64_t seed) {
  // Area lights drawn by an emissive proxy come from the proxy's triangles below.
  std::vector<bool> proxied(scene.lights.size(), false);
  for (std::size_t i = 0; i < scene.lights.size(); ++i)
    proxied[i] = scene.lights[i].type == ReferenceLight::Type::Area && index.light_has_proxy[i];
  std::vector<PointEmitter> out = light_point_emitters(scene.lights, area_samples, seed, &proxied);
  const int side = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(std::max(1, area_samples))))));
  const auto strata = static_cast<float>(side * side);
  // Emissive triangles of static instances.
  const auto& instances = scene.geometry.instances;
  for (std::size_t k = 0; k < instances.size(); ++k) {
    if (instances[k].dynamic) continue;
    const auto [first, end] = instance_triangles(index, k);
    for (std::uint32_t t = first; t < end; ++t) {
      const ShadingTriangle& tri = index.triangles[t];
      const ReferenceMaterial& m = scene.materials[tri.material];
      if (m.emission == glm::vec3(0.0f) || !(tri.area_m2 > 0.0f)) continue;
      Pcg32 rng = Pcg32::for_item(seed, 0x45000000ULL + t);
      stratified(side, rng, [&](float u, float v) {
        const float su = std::sqrt(u);  // uniform on the triangle
        PointEmitter p;
        p.kind = PointEmitter::Kind::Lambertian;
        p.position = tri.p0 + su * (1.0f - v) * tri.e1 + su * v * tri.e2;
        p.direction = tri.face_normal;
        // The emissive texture at the point, read at the level of its stratum's size.
        p.radiant = kPi * emission_at(scene, tri, glm::vec2(su * (1.0f - v), su * v), std::sqrt(tri.area_m2 / strata)) *
                    tri.area_m2 / strata;
        p.area_m2 = tri.area_m2 / strata;
        p.two_sided = m.double_sided;
        p.drawn_live = tri.emitter >= 0 && index.emitters.stands_for_light[static_cast<std::size_t>(tri.emitter)] != 0;
        out.push_back(p);
      });
    }
  }
  return out;
}

float lambertian_kernel(const glm::vec3& q, const glm::vec3& nq, float emitter_area_m2, bool two_sided,
                        const glm::vec3& p, const glm::vec3& n, float receiver_area_m2) {
  const glm::vec3 d = p - q;
  const float d2 = glm::dot(d, d);
  if (!(d2 > 0.0f)) return 0.0f;
  const glm::vec3 w = d / std::sqrt(d2);
  float cos_q = glm::dot(nq, w);
  if (two_sided) cos_q = std::fabs(cos_q);
  const float cos_p = -glm::dot(n, w);
  if (cos_q <= 0.0f || cos_p <= 0.0f) return 0.0f;
  return cos_q * cos_p / (kPi * d2 + emitter_area_m2 + receiver_area_m2);
}

glm::vec3 emitter_irradiance(const PointEmitter& e, const glm::vec3& p, const glm::vec3& n, float receiver_area_m2) {
  switch (e.kind) {
    case PointEmitter::Kind::Directional:
      return e.radiant * std::max(0.0f, -glm::dot(n, e.direction));
    case PointEmitter::Kind::Lambertian:
      return e.radiant * lambertian_kernel(e.position, e.direction, e.area_m2, e.two_sided, p, n, receiver_area_m2);
    case PointEmitter::Kind::Punctual:
      break;
  }
  const glm::vec3 to = e.position - p;
  const float d2 = glm::dot(to, to);
  if (!(d2 > 0.0f)) return glm::vec3(0.0f);
  const float d = std::sqrt(d2);
  const glm::vec3 wi = to / d;
  const float cos_p = glm::dot(n, wi);
  if (cos_p <= 0.0f) return glm::vec3(0.0f);
  float atten = range_window(d, e.range_m) * cos_p / (d2 + receiver_area_m2 / kPi);
  if (e.spot) atten *= spot_cone(e.direction, e.cos_outer, e.cos_inner, wi);
  return e.radiant * atten;
}

namespace {

// The side^2 stratified directions of punctual_lit_solid_angle (the same floats every call:
// computed once per side, kept for the process; a few sides are ever used).
const std::vector<glm::vec3>& sphere_directions(int side) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<const std::vector<glm::vec3>>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& table = tables[side];
  if (!table) {
    std::vector<glm::vec3> dirs;
    dirs.reserve(static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
    for (int a = 0; a < side; ++a)
      for (int b = 0; b < side; ++b) {
        const float z = 1.0f - 2.0f * (static_cast<float>(a) + 0.5f) / static_cast<float>(side);
        const float phi = 2.0f * kPi * (static_cast<float>(b) + 0.5f) / static_cast<float>(side);
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
      }
    table = std::make_unique<const std::vector<glm::vec3>>(std::move(dirs));
  }
  return *table;
}

}  // namespace

double punctual_lit_solid_angle(const PointEmitter& e, const RayCaster& caster, int side,
                                std::vector<LitDirection>* hits, ThreadPool* pool) {
  const float per_direction = 4.0f * kPi / static_cast<float>(side * side);
  // The directions inside the spot cone (all for a point light), traced as one stream: all
  // leave one point, so the caster may trace them as packets.
  const std::vector<glm::vec3>& dirs = sphere_directions(side);
  std::vector<Ray> rays;
  std::vector<float> weights;
  rays.reserve(dirs.size());
  weights.reserve(dirs.size());
  for (const glm::vec3& w : dirs) {
    const float weight = e.spot ? spot_cone(e.direction, e.cos_outer, e.cos_inner, -w) : 1.0f;
    if (weight <= 0.0f) continue;
    rays.push_back(Ray{e.position, 0.0f, w});
    weights.push_back(weight);
  }
  std::vector<Hit> found(rays.size());
  if (pool != nullptr && pool->size() > 1) {
    // Chunks of 64 packets: each hit lands in its own slot, so any split gives the same sum.
    constexpr std::size_t kChunk = 1024;
    const std::span<const Ray> all(rays);
    const std::span<Hit> out(found);
    pool->parallel_for((rays.size() + kChunk - 1) / kChunk, [&](std::size_t c) {
      const std::size_t first = c * kChunk, n = std::min(kChunk, rays.size() - first);
      caster.intersect_many(all.subspan(first, n), out.subspan(first, n));
    });
  } else {
    caster.intersect_many(rays, found);
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit& h = found[i];
    if (!h.valid()) continue;
    const glm::vec3& w = rays[i].direction;
    // The back of a one-sided surface receives nothing (a light inside a closed box or
    // behind a wall lights only those).
    const glm::vec3 n = glm::normalize(h.geometric_normal);
    if (glm::dot(n, w) >= 0.0f) continue;
    const float weight = weights[i] * range_window(h.t, e.range_m);
    sum += static_cast<double>(weight);
    if (hits && weight > 0.0f) hits->push_back({e.position + w * h.t, n, weight * per_direction});
  }
  return static_cast<double>(per_direction) * sum;
}

namespace {

Ray segment_ray(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb) {
  const glm::vec3 o = offset_ray_origin(a, na);
  const glm::vec3 t = offset_ray_origin(b, nb);
  return Ray{o, 0.0f, t - o, 1.0f};
}

}  // namespace

bool segment_visible(const RayCaster& caster, const glm::vec3& a, const glm::vec3& na, const glm::vec3& b,
                     const glm::vec3& nb) {
  return !caster.occluded(segment_ray(a, na, b, nb));
}

Ray emitter_shadow_ray(const PointEmitter& e, const glm::vec3& p, const glm::vec3& n) {
  switch (e.kind) {
    case PointEmitter::Kind::Directional:
      return Ray{offset_ray_origin(p, n), 0.0f, -e.direction};
    case PointEmitter::Kind::Punctual: {
      const glm::vec3 o = offset_ray_origin(p, n);
      return Ray{o, 0.0f, e.position - o, 1.0f};
    }
    case PointEmitter::Kind::Lambertian:
      break;
  }
  const glm::vec3 ne = glm::dot(e.direction, p - e.position) >= 0.0f ? e.direction : -e.direction;
  return segment_ray(p, n, e.position, ne);
}

bool emitter_visible(const RayCaster& caster, const PointEmitter& e, const glm::vec3& p, const glm::vec3& n) {
  return !caster.occluded(emitter_shadow_ray(e, p, n));
}

}  // namespace gi
