#pragma once
// One-sample estimators of the reference path tracer over a flattened scene: radiance
// along a camera ray and irradiance at a surface point. The drivers (reference_render.h)
// run them over pixels and points in parallel.
//   gi::PathTracer pt(scene, index, caster, {.max_bounces = -1});
//   glm::vec3 L = pt.radiance(camera_ray, rng);

#include <limits>
#include <optional>

#include <glm/glm.hpp>

#include "core/random.h"
#include "raytrace/ray.h"
#include "raytrace/ray_caster.h"
#include "raytrace/reference_brdf.h"
#include "raytrace/reference_scene.h"

namespace gi {

struct PathTracerSettings {
  int max_bounces = -1;            ///< Indirect bounces; -1: unlimited; 0: direct only.
  int russian_roulette_start = 3;  ///< Path vertex from which Russian roulette applies.
  int max_vertices = 1024;         ///< Safety stop (with albedo <= 0.95 the cut energy is < 1e-22).
  /// Ray cones for texture lookups (material_lookup.h): a path's footprint at a hit is the
  /// sum over its segments of length x spread, the spread starting at camera_spread_rad
  /// (0: camera rays read the finest mip level; many samples per pixel average the texture)
  /// and growing by bounce_spread_rad at every scattering. The default gives a footprint of
  /// 0.2 m ten metres after a bounce: the texture is averaged over what one bounce ray's
  /// sample stands for without blurring texture detail the lighting correlates with.
  float camera_spread_rad = 0.0f;
  float bounce_spread_rad = 0.02f;
};

class PathTracer {
 public:
  PathTracer(const ReferenceScene& scene, const ReferenceSceneIndex& index, const RayCaster& caster,
             PathTracerSettings settings);

  /// Radiance arriving along `ray` (unit direction) from the scene: emission seen, direct
  /// and indirect reflected light.
  glm::vec3 radiance(const Ray& ray, Pcg32& rng) const;

  /// radiance() without the emission (and sky) found at the ray's first hit: the light that
  /// surface reflects towards the ray's origin, i.e. the indirect light arriving there along
  /// the ray (what directional light maps hold).
  glm::vec3 reflected_radiance(const Ray& ray, Pcg32& rng) const;

  struct Irradiance {
    glm::vec3 direct{0.0f};
    glm::vec3 indirect{0.0f};
  };
  /// One-sample irradiance estimate at `p` on the side of unit normal `n`. `face`: the unit
  /// geometric normal of the surface under `p` (zero: none); light from below its plane is
  /// dark, as for the light atlas's gather (the surface cannot see its own front).
  Irradiance irradiance(const glm::vec3& p, const glm::vec3& n, Pcg32& rng,
                        const glm::vec3& face = glm::vec3(0.0f)) const;

 private:
  struct Traced {
    glm::vec3 emitted{0.0f};    ///< Emission (or sky) found at the ray's first hit, MIS-weighted.
    glm::vec3 reflected{0.0f};  ///< Everything reflected at the first hit and beyond.
  };
  /// Follows a path from `ray`. `prev_pdf` is the solid-angle density of the ray's direction
  /// (0: not BRDF-sampled, no MIS). Light may reach the path at vertices 1..max_light_vertex.
  Traced trace(Ray ray, float prev_pdf, int max_light_vertex, Pcg32& rng) const;
  /// Next-event estimation at a surface point: every analytic light plus one emitter. A
  /// nonzero `face` (a receiver's geometric normal) drops the light from below its plane.
  glm::vec3 direct_light(const glm::vec3& origin, const glm::vec3& p, const ReferenceBrdf& brdf, const glm::vec3& wo,
                         Pcg32& rng, const glm::vec3& face = glm::vec3(0.0f)) const;
  /// direct_light()'s emitter sample: the emitter triangle picked by u_pick and its point at
  /// (u1, u2), MIS-weighted; nullopt when it adds nothing.
  std::optional<glm::vec3> emitter_light(const glm::vec3& origin, const glm::vec3& p, const ReferenceBrdf& brdf,
                                         const glm::vec3& wo, float u_pick, float u1, float u2,
                                         const glm::vec3& face = glm::vec3(0.0f)) const;
  /// Solid-angle density with which direct_light() samples a point on emitter triangle t.
  float emitter_pdf(const ShadingTriangle& t, float distance2, float cos_light) const;

  const ReferenceScene& scene_;
  const ReferenceSceneIndex& index_;
  const RayCaster& caster_;
  PathTracerSettings settings_;
};

}  // namespace gi
