#pragma once
// The light sources of a light-atlas bake as point emitters (Schärfig et al. 2016, §3.2 and
// §5.3): punctual lights stay points, directional lights stay directions, and area lights and
// emissive static triangles become stratified grids of Lambertian points sharing their power.
// VPLs shoot through the same Lambertian kernel.
//
// Near-field treatment (documented in docs/light_atlas.md): the point-to-point form factor
// cos cos / (pi d^2) diverges as d -> 0. Every kernel here replaces d^2 by
// d^2 + (A_emitter + A_receiver) / pi, where A is the area the emitter / receiver point
// stands for. For one disc on the axis of a point this is the exact disc-point form factor
// (A/pi) / (d^2 + A/pi); far away it tends to 1/d^2; at contact it is bounded by the
// irradiance of an infinite plane of the same radiosity. So no sample, VPL or texel spikes
// when a light or a VPL touches a surface.
//   auto emitters = gi::point_emitters(scene, index, 64);
//   glm::vec3 e = gi::emitter_irradiance(emitters[0], p, n, texel_area);

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "raytrace/ray_caster.h"
#include "raytrace/reference_scene.h"

namespace gi {

class ThreadPool;

struct PointEmitter {
  enum class Kind : std::uint8_t { Punctual, Directional, Lambertian };
  Kind kind = Kind::Punctual;
  glm::vec3 position{0.0f};
  /// Punctual: spot axis; Directional: direction light travels; Lambertian: unit normal.
  glm::vec3 direction{0.0f, -1.0f, 0.0f};
  /// Punctual: intensity W/sr; Directional: irradiance W/m^2; Lambertian: power W (per side).
  glm::vec3 radiant{0.0f};
  float area_m2 = 0.0f;  ///< Lambertian: the area the point stands for.
  bool spot = false;
  bool two_sided = false;  ///< Lambertian: emits from both sides.
  /// False for the points of an emissive triangle no light stands for: the renderer draws
  /// no light of it, so a bake holds its direct light (the static lights' and their proxies'
  /// points are true: drawn live).
  bool drawn_live = true;
  float range_m = 0.0f;
  float cos_outer = -1.0f;
  float cos_inner = 1.0f;
};

/// Point emitters of the scene's enabled lights and static emissive triangles. Area lights
/// drawn by an emissive proxy (ReferenceSceneIndex::light_has_proxy) come from the proxy's
/// triangles only. `area_samples` points per area light or emissive triangle (a square grid
/// of at least that many strata, jittered from `seed`).
std::vector<PointEmitter> point_emitters(const ReferenceScene& scene, const ReferenceSceneIndex& index,
                                         int area_samples, std::uint64_t seed);

/// Point emitters of `lights` alone (no emissive geometry; area lights become `area_samples`
/// Lambertian points each, 1 mm in front of the light's plane so the panel a scene draws for
/// the light does not shadow them): what a runtime relighting of moving lights and the
/// dynamic objects' direct light need.
/// `skip[i]` (optional, same size) leaves light i out.
std::vector<PointEmitter> light_point_emitters(std::span<const ReferenceLight> lights, int area_samples,
                                               std::uint64_t seed, const std::vector<bool>* skip = nullptr);

/// Unshadowed irradiance (W/m^2) at point p with unit normal n, the receiver standing for
/// `receiver_area_m2`, from emitter e (the regularized kernels above).
glm::vec3 emitter_irradiance(const PointEmitter& e, const glm::vec3& p, const glm::vec3& n, float receiver_area_m2);

/// Lambertian kernel: irradiance per watt at (p, n) from a Lambertian point at q with unit
/// normal nq standing for area `emitter_area_m2`: cos_q cos_p / (pi (d^2 + (A_q + A_p)/pi)).
float lambertian_kernel(const glm::vec3& q, const glm::vec3& nq, float emitter_area_m2, bool two_sided,
                        const glm::vec3& p, const glm::vec3& n, float receiver_area_m2);

/// True when the segment between surface point p (unit normal n) and the emitter is free.
/// Surface end points are moved off their surfaces (ray_offset.h) so neither self-shadows.
bool emitter_visible(const RayCaster& caster, const PointEmitter& e, const glm::vec3& p, const glm::vec3& n);

/// The shadow ray emitter_visible traces: emitter_visible(c, e, p, n) == !c.occluded(emitter_shadow_ray(e, p, n)).
/// For tracing many at once (RayCaster::occluded_coherent).
Ray emitter_shadow_ray(const PointEmitter& e, const glm::vec3& p, const glm::vec3& n);

/// Solid angle (sr) of static geometry lit by punctual emitter e, weighted by its spot cone
/// and range window: 4 pi / N x the sum over N = side^2 stratified directions of cone x
/// window x hit (front faces only: the back of a one-sided surface receives nothing).
/// I x this is the flux the light sends onto the scene. `hits` (optional)
/// receives every hit point with the solid angle it stands for (weighted). `pool` (optional)
/// traces the rays in chunks over its threads; the result is the same bit for bit.
struct LitDirection {
  glm::vec3 point;
  glm::vec3 normal;  ///< Unit geometric normal (front side, facing the light).
  float solid_angle_sr;
};
double punctual_lit_solid_angle(const PointEmitter& e, const RayCaster& caster, int side,
                                std::vector<LitDirection>* hits = nullptr, ThreadPool* pool = nullptr);

/// True when the segment between two surface points (each with its unit normal, on the
/// side facing the other) is free.
bool segment_visible(const RayCaster& caster, const glm::vec3& a, const glm::vec3& na, const glm::vec3& b,
                     const glm::vec3& nb);

}  // namespace gi
