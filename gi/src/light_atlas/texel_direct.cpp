#include "light_atlas/texel_direct.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "light_atlas/texel_sampling.h"
#include "raytrace/light_falloff.h"
#include "raytrace/material_lookup.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"

namespace gi {
namespace {

// The light sampling of one texel: its point, normals and ray origin, the samples per light
// (each weighing inv = 1 / samples) and the shadow rays counted.
struct TexelLighting {
  const StaticBakeScene& b;
  glm::vec3 p, n, face, origin;
  int samples;
  double inv;
  std::uint64_t* rays;
};

// An area light without emissive geometry: `samples` stratified points over its rectangle.
void sample_area_light(const TexelLighting& t, const ReferenceLight& l, Pcg32& rng, glm::dvec3& sum) {
  const float area = 4.0f * glm::length(l.half_x) * glm::length(l.half_y);
  const float shift_y = rng.next_float();  // drawn first: see random.h
  const glm::vec2 shift(rng.next_float(), shift_y);
  for (int s = 0; s < t.samples; ++s) {
    const glm::vec2 u = hammersley(static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(t.samples), shift);
    const glm::vec3 q = l.position + (2.0f * u.x - 1.0f) * l.half_x + (2.0f * u.y - 1.0f) * l.half_y;
    const glm::vec3 to = q - t.p;
    const float d2 = glm::dot(to, to);
    if (!(d2 > 0.0f)) continue;
    const glm::vec3 wi = to / std::sqrt(d2);
    const float cos_l = -glm::dot(wi, l.direction), cos_r = glm::dot(wi, t.n);
    if (cos_l <= 0.0f || cos_r <= 0.0f || glm::dot(wi, t.face) <= 0.0f) continue;
    ++*t.rays;
    if (t.b.caster->occluded(Ray{t.origin, 0.0f, q - t.origin, 1.0f})) continue;
    sum += glm::dvec3(l.radiant * (cos_r * cos_l * area / d2)) * t.inv;
  }
}

// A disc (the sun's angular radius): `samples` stratified directions uniform over its
// cone, each carrying radiant / samples; soft shadows (docs/scene-format.md). Where they
// disagree (a penumbra: some occluded, some not), kPenumbraFactor x `samples` more, and the
// mean over all: 8 directions step a 9 cm penumbra (Dabrovic Sponza's arcades at 8 texels/m)
// in eighths of the sun, 20-25% off the path tracer at single texels, the sun's shadow edges
// a quarter of the whole lightmap's error. Where the first directions agree, a few on the
// disc's rim look for a penumbra's sliver they missed (the decision biases only what all of
// those miss too).
void sample_sun_disc(const TexelLighting& t, const ReferenceLight& l, Pcg32& rng, glm::dvec3& sum) {
  constexpr int kPenumbraFactor = 8;
  glm::dvec3 lit(0.0);
  int shadowed = 0, unshadowed = 0;
  const auto pass = [&](int n) {
    const float shift_y = rng.next_float();  // drawn first: see random.h
    const glm::vec2 shift(rng.next_float(), shift_y);
    for (int s = 0; s < n; ++s) {
      const glm::vec2 u = hammersley(static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(n), shift);
      const glm::vec3 wi = sample_cone(-l.direction, l.cos_disc, u.x, u.y);
      const float cos_r = glm::dot(wi, t.n);
      if (cos_r <= 0.0f || glm::dot(wi, t.face) <= 0.0f) continue;
      ++*t.rays;
      if (t.b.caster->occluded(Ray{t.origin, 0.0f, wi, std::numeric_limits<float>::infinity()})) {
        ++shadowed;
        continue;
      }
      ++unshadowed;
      lit += glm::dvec3(l.radiant * cos_r);
    }
  };
  pass(t.samples);
  int taken = t.samples;
  // The first directions all agree: kRimProbes more on the disc's rim, where a penumbra's
  // sliver shows first, tell whether it ends here (they only decide; they are not counted).
  bool penumbra = shadowed > 0 && unshadowed > 0;
  if (t.samples > 1 && !penumbra && shadowed + unshadowed > 0) {
    constexpr int kRimProbes = 6;
    const float phase = rng.next_float();
    for (int k = 0; k < kRimProbes && !penumbra; ++k) {
      const glm::vec3 wi = sample_cone(-l.direction, l.cos_disc, 1.0f, (static_cast<float>(k) + phase) / kRimProbes);
      if (glm::dot(wi, t.n) <= 0.0f || glm::dot(wi, t.face) <= 0.0f) continue;
      ++*t.rays;
      const bool occluded = t.b.caster->occluded(Ray{t.origin, 0.0f, wi, std::numeric_limits<float>::infinity()});
      penumbra = occluded != (shadowed > 0);
    }
  }
  if (t.samples > 1 && penumbra) {
    pass(kPenumbraFactor * t.samples);
    taken += kPenumbraFactor * t.samples;
  }
  sum += lit / static_cast<double>(taken);
}

// A point, spot or sharp directional light: one shadow ray.
void sample_point_light(const TexelLighting& t, const ReferenceLight& l, glm::dvec3& sum) {
  glm::vec3 wi;
  float atten = 1.0f, t_max = 1.0f;
  glm::vec3 dir;
  if (l.type == ReferenceLight::Type::Directional) {
    wi = -l.direction;
    dir = wi;
    t_max = std::numeric_limits<float>::infinity();
  } else {
    const glm::vec3 to = l.position - t.p;
    const float d2 = std::max(glm::dot(to, to), 1e-12f);
    const float d = std::sqrt(d2);
    wi = to / d;
    atten = range_window(d, l.range_m) / d2;
    if (l.type == ReferenceLight::Type::Spot) atten *= spot_cone(l.direction, l.cos_outer, l.cos_inner, wi);
    dir = l.position - t.origin;
  }
  const float cos_r = glm::dot(wi, t.n);
  if (atten <= 0.0f || cos_r <= 0.0f || glm::dot(wi, t.face) <= 0.0f) return;
  ++*t.rays;
  if (t.b.caster->occluded(Ray{t.origin, 0.0f, dir, t_max})) return;
  sum += glm::dvec3(l.radiant * (atten * cos_r));
}

// The emissive triangles: `samples` stratified picks by power, each a stratified point; into
// `sum` for those that stand for a light, `unlit` for the others.
void sample_emitters(const TexelLighting& t, Pcg32& rng, glm::dvec3& sum, glm::dvec3& unlit) {
  const StaticBakeScene& b = t.b;
  const EmitterTable& em = b.index.emitters;
  const float shift_y = rng.next_float();  // drawn first: see random.h
  const glm::vec2 shift(rng.next_float(), shift_y);
  const float pick_shift = rng.next_float();
  for (int s = 0; s < t.samples; ++s) {
    float u_pick = (static_cast<float>(s) + pick_shift) / static_cast<float>(t.samples);
    u_pick = std::min(u_pick, 0x1.fffffep-1f);
    const auto k = static_cast<std::size_t>(std::lower_bound(em.cdf.begin(), em.cdf.end(), u_pick) - em.cdf.begin());
    const std::size_t pick = std::min(k, em.triangle.size() - 1);
    const ShadingTriangle& tri = b.index.triangles[em.triangle[pick]];
    const ReferenceMaterial& mat = b.scene.materials[tri.material];
    const float prob = em.probability[pick];
    const glm::vec2 u = hammersley(static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(t.samples), shift);
    const float su = std::sqrt(u.x);
    const glm::vec3 q = tri.p0 + su * (1.0f - u.y) * tri.e1 + su * u.y * tri.e2;
    const glm::vec3 to = q - t.p;
    const float d2 = glm::dot(to, to);
    if (!(d2 > 0.0f) || !(prob > 0.0f)) continue;
    const glm::vec3 wi = to / std::sqrt(d2);
    float cos_l = -glm::dot(wi, tri.face_normal);
    if (mat.double_sided) cos_l = std::fabs(cos_l);
    const float cos_r = glm::dot(wi, t.n);
    if (cos_l <= 0.0f || cos_r <= 0.0f || glm::dot(wi, t.face) <= 0.0f) continue;
    ++*t.rays;
    if (b.caster->occluded(Ray{t.origin, 0.0f, q - t.origin, 0.9999f})) continue;
    const glm::vec3 emission = emission_at(b.scene, tri, glm::vec2(su * (1.0f - u.y), su * u.y), 0.0f);
    (em.stands_for_light[pick] != 0 ? sum : unlit) +=
        glm::dvec3(emission * (cos_r * cos_l * tri.area_m2 / (prob * d2))) * t.inv;
  }
}

}  // namespace

DirectAt direct_at(const StaticBakeScene& b, const glm::vec3& p, const glm::vec3& n, const glm::vec3& face, int samples,
                   Pcg32& rng, std::uint64_t* rays, DirectLights which) {
  const TexelLighting t{b, p, n, face, offset_ray_origin(p, face), samples, 1.0 / static_cast<double>(samples), rays};
  const bool all = which == DirectLights::All;
  glm::dvec3 sum(0.0), area(0.0);
  for (std::size_t i = 0; i < b.scene.lights.size(); ++i) {
    const ReferenceLight& l = b.scene.lights[i];
    if (l.type == ReferenceLight::Type::Area) {
      // Else its emissive geometry stands for it.
      if (all && !b.index.light_has_proxy[i]) sample_area_light(t, l, rng, area);
    } else if (l.type == ReferenceLight::Type::Directional && l.cos_disc < 1.0f) {
      sample_sun_disc(t, l, rng, sum);
    } else {
      sample_point_light(t, l, sum);
    }
  }
  if (!all || b.index.emitters.triangle.empty()) return {glm::vec3(sum + area), glm::vec3(0.0f), glm::vec3(area)};
  glm::dvec3 lit(0.0), unlit(0.0);
  sample_emitters(t, rng, lit, unlit);
  return {glm::vec3(sum + area + lit), glm::vec3(unlit), glm::vec3(area + lit + unlit)};
}

}  // namespace gi
