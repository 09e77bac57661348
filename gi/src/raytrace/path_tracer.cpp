#include "raytrace/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/color.h"
#include "raytrace/light_falloff.h"
#include "raytrace/material_lookup.h"
#include "raytrace/ray_offset.h"

namespace gi {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr int kUnlimited = std::numeric_limits<int>::max();

// Power heuristic (Veach 1997, eq. 9.13, beta = 2) for the strategy with density a.
float power_heuristic(float a, float b) {
  const float a2 = a * a;
  const float b2 = b * b;
  return a2 + b2 > 0.0f && std::isfinite(a2 + b2) ? a2 / (a2 + b2) : (a > b ? 1.0f : 0.0f);
}

float spot_factor(const ReferenceLight& l, const glm::vec3& to_light) {
  return spot_cone(l.direction, l.cos_outer, l.cos_inner, to_light);
}

// Light from below a receiver's own plane is dark (a zero face: no such receiver).
bool below_face(const glm::vec3& wi, const glm::vec3& face) {
  return face != glm::vec3(0.0f) && glm::dot(wi, face) <= 0.0f;
}

}  // namespace

PathTracer::PathTracer(const ReferenceScene& scene, const ReferenceSceneIndex& index, const RayCaster& caster,
                       PathTracerSettings settings)
    : scene_(scene), index_(index), caster_(caster), settings_(settings) {}

float PathTracer::emitter_pdf(const ShadingTriangle& t, float distance2, float cos_light) const {
  if (cos_light <= 0.0f || t.area_m2 <= 0.0f) return 0.0f;
  return index_.emitters.probability[static_cast<std::size_t>(t.emitter)] * distance2 / (cos_light * t.area_m2);
}

glm::vec3 PathTracer::direct_light(const glm::vec3& origin, const glm::vec3& p, const ReferenceBrdf& brdf,
                                   const glm::vec3& wo, Pcg32& rng, const glm::vec3& face) const {
  glm::vec3 sum(0.0f);
  for (std::size_t i = 0; i < scene_.lights.size(); ++i) {
    const ReferenceLight& l = scene_.lights[i];
    switch (l.type) {
      case ReferenceLight::Type::Point:
      case ReferenceLight::Type::Spot: {
        const glm::vec3 to = l.position - p;
        const float d2 = std::max(glm::dot(to, to), 1e-12f);
        const float d = std::sqrt(d2);
        const glm::vec3 wi = to / d;
        const glm::vec3 fcos = brdf.eval_cos(wo, wi);
        if (fcos == glm::vec3(0.0f) || below_face(wi, face)) break;
        float atten = range_window(d, l.range_m) / d2;
        if (l.type == ReferenceLight::Type::Spot) atten *= spot_factor(l, wi);
        if (atten <= 0.0f) break;
        if (caster_.occluded(Ray{origin, 0.0f, l.position - origin, 1.0f})) break;
        sum += l.radiant * atten * fcos;
        break;
      }
      case ReferenceLight::Type::Directional: {
        glm::vec3 wi = -l.direction;
        if (l.cos_disc < 1.0f) {  // a disc (the sun's): a direction uniform over its cone
          const float u = rng.next_float();
          wi = sample_cone(-l.direction, l.cos_disc, u, rng.next_float());
        }
        const glm::vec3 fcos = brdf.eval_cos(wo, wi);
        if (fcos == glm::vec3(0.0f) || below_face(wi, face)) break;
        if (caster_.occluded(Ray{origin, 0.0f, wi})) break;
        sum += l.radiant * fcos;
        break;
      }
      case ReferenceLight::Type::Area: {
        // Two numbers are drawn whatever happens, so streams stay aligned across pixels.
        const float u = rng.next_float();
        const float v = rng.next_float();
        if (index_.light_has_proxy[i]) break;  // its emissive geometry is sampled below
        const glm::vec3 q = l.position + (2.0f * u - 1.0f) * l.half_x + (2.0f * v - 1.0f) * l.half_y;
        const glm::vec3 to = q - p;
        const float d2 = glm::dot(to, to);
        if (!(d2 > 0.0f)) break;
        const glm::vec3 wi = to / std::sqrt(d2);
        const float cos_light = -glm::dot(wi, l.direction);
        if (cos_light <= 0.0f) break;
        const glm::vec3 fcos = brdf.eval_cos(wo, wi);
        if (fcos == glm::vec3(0.0f) || below_face(wi, face)) break;
        if (caster_.occluded(Ray{origin, 0.0f, q - origin, 1.0f})) break;
        const float area = 4.0f * glm::length(l.half_x) * glm::length(l.half_y);
        sum += l.radiant * fcos * (cos_light * area / d2);
        break;
      }
    }
  }

  const float u_pick = rng.next_float();
  const float u1 = rng.next_float();
  const float u2 = rng.next_float();
  if (const std::optional<glm::vec3> e = emitter_light(origin, p, brdf, wo, u_pick, u1, u2, face)) return sum + *e;
  return sum;
}

std::optional<glm::vec3> PathTracer::emitter_light(const glm::vec3& origin, const glm::vec3& p,
                                                   const ReferenceBrdf& brdf, const glm::vec3& wo, float u_pick,
                                                   float u1, float u2, const glm::vec3& face) const {
  const EmitterTable& em = index_.emitters;
  if (em.triangle.empty()) return std::nullopt;
  const auto pick = static_cast<std::size_t>(std::lower_bound(em.cdf.begin(), em.cdf.end(), u_pick) - em.cdf.begin());
  const ShadingTriangle& t = index_.triangles[em.triangle[std::min(pick, em.triangle.size() - 1)]];
  const ReferenceMaterial& mat = scene_.materials[t.material];
  const float su = std::sqrt(u1);
  const glm::vec2 bary(su * (1.0f - u2), su * u2);
  // Uniform on the triangle: p0 + sqrt(u1) (1 - u2) e1 + sqrt(u1) u2 e2.
  const glm::vec3 q = t.p0 + su * (1.0f - u2) * t.e1 + su * u2 * t.e2;
  const glm::vec3 to = q - p;
  const float d2 = glm::dot(to, to);
  if (!(d2 > 0.0f)) return std::nullopt;
  const glm::vec3 wi = to / std::sqrt(d2);
  float cos_light = -glm::dot(wi, t.face_normal);
  if (mat.double_sided) cos_light = std::fabs(cos_light);
  const float pdf_light = emitter_pdf(t, d2, cos_light);
  if (!(pdf_light > 0.0f) || !std::isfinite(pdf_light)) return std::nullopt;
  const glm::vec3 fcos = brdf.eval_cos(wo, wi);
  if (fcos == glm::vec3(0.0f)) return std::nullopt;
  if (below_face(wi, face)) return std::nullopt;
  // Stop just short of the emitter so it does not occlude itself.
  if (caster_.occluded(Ray{origin, 0.0f, q - origin, 0.9999f})) return std::nullopt;
  const float weight = power_heuristic(pdf_light, brdf.pdf(wo, wi));
  return emission_at(scene_, t, bary, 0.0f) * fcos * (weight / pdf_light);
}

PathTracer::Traced PathTracer::trace(Ray ray, float prev_pdf, int max_light_vertex, Pcg32& rng) const {
  Traced out;
  glm::vec3 beta(1.0f);
  float spread = settings_.camera_spread_rad;  // ray cone: footprint width_m at the hit
  float width_m = 0.0f;
  for (int k = 1; k <= settings_.max_vertices; ++k) {
    glm::vec3& sink = k == 1 ? out.emitted : out.reflected;
    const Hit hit = caster_.intersect(ray);
    if (!hit.valid()) {
      if (k <= max_light_vertex)
        sink += beta * engine::sky_radiance(scene_.sky_radiance, scene_.sky_gradient, glm::normalize(ray.direction));
      break;
    }
    const ShadingTriangle& tri = index_.triangles[index_.instance_first[hit.instance] + hit.primitive];
    const ReferenceMaterial& mat = scene_.materials[tri.material];
    const glm::vec3 wo = -ray.direction;
    const bool front = glm::dot(tri.face_normal, wo) > 0.0f;
    if (!front && !mat.double_sided) break;  // the back of a one-sided surface: opaque and black
    const glm::vec3 p = tri.p0 + hit.barycentric.x * tri.e1 + hit.barycentric.y * tri.e2;
    width_m += hit.t * glm::length(ray.direction) * spread;

    if (tri.emitter >= 0 && k <= max_light_vertex) {
      float weight = 1.0f;
      if (prev_pdf > 0.0f) {
        const float cos_light = std::fabs(glm::dot(tri.face_normal, wo));
        weight = power_heuristic(prev_pdf, emitter_pdf(tri, hit.t * hit.t, cos_light));
      }
      sink += beta * emission_at(scene_, tri, hit.barycentric, width_m) * weight;
    }
    if (k + 1 > max_light_vertex) break;

    const ReferenceBrdf brdf = shading_brdf(scene_, tri, hit.barycentric, front, width_m);
    const glm::vec3 facing = front ? tri.face_normal : -tri.face_normal;
    const glm::vec3 origin = offset_ray_origin(p, facing);
    out.reflected += beta * direct_light(origin, p, brdf, wo, rng);

    const float u_lobe = rng.next_float();
    const float u1 = rng.next_float();
    const float u2 = rng.next_float();
    const float u_rr = rng.next_float();
    BrdfSample s;
    if (!brdf.sample(wo, u_lobe, u1, u2, s)) break;
    if (glm::dot(s.wi, facing) <= 0.0f) break;  // a shading normal may send it through the surface
    beta *= s.weight;
    prev_pdf = s.pdf;
    if (k + 1 >= settings_.russian_roulette_start) {
      const float survive = std::min(0.95f, max_component(beta));
      if (!(u_rr < survive)) break;
      beta /= survive;
    }
    ray = Ray{origin, 0.0f, s.wi};
    spread += settings_.bounce_spread_rad;
  }
  return out;
}

glm::vec3 PathTracer::radiance(const Ray& ray, Pcg32& rng) const {
  const int max_e = settings_.max_bounces < 0 ? kUnlimited : settings_.max_bounces + 2;
  const Traced t = trace(ray, 0.0f, max_e, rng);
  return t.emitted + t.reflected;
}

glm::vec3 PathTracer::reflected_radiance(const Ray& ray, Pcg32& rng) const {
  const int max_e = settings_.max_bounces < 0 ? kUnlimited : settings_.max_bounces + 2;
  return trace(ray, 0.0f, max_e, rng).reflected;
}

PathTracer::Irradiance PathTracer::irradiance(const glm::vec3& p, const glm::vec3& n, Pcg32& rng,
                                              const glm::vec3& face) const {
  // The receiver is a cosine lobe: "BRDF x cos" = cos, sampled with density cos / pi.
  ReferenceBrdf receiver;
  receiver.normal = n;
  receiver.material = engine::gltf_lambertian(glm::vec3(kPi));
  // Off the surface along its face, as the gather's rays (light_atlas/texel_gather.cpp).
  const glm::vec3 origin = offset_ray_origin(p, face != glm::vec3(0.0f) ? face : n);
  Irradiance e;
  e.direct = direct_light(origin, p, receiver, n, rng, face);
  const float u2 = rng.next_float();  // drawn first: see random.h
  const float u1 = rng.next_float();
  const glm::vec3 wi = sample_cosine_hemisphere(n, u1, u2);
  const float pdf = std::max(glm::dot(wi, n), 0.0f) / kPi;
  if (!(pdf > 0.0f)) return e;
  // Below the surface's own plane (a shading normal off the face): the ray would see the
  // front of the very surface it leaves, light the point cannot receive.
  if (glm::dot(wi, face) < 0.0f) return e;
  const int max_e = settings_.max_bounces < 0 ? kUnlimited : settings_.max_bounces + 1;
  const Traced t = trace(Ray{origin, 0.0f, wi}, pdf, max_e, rng);
  e.direct += kPi * t.emitted;  // L cos / pdf = pi L
  e.indirect = kPi * t.reflected;
  return e;
}

}  // namespace gi
