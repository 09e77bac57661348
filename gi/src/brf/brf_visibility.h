#pragma once
// Visibility between a rigid object and the points that receive its bounce (the V of
// Iwasaki et al.'s eq. 12-13, which this implementation takes out of the integral): the
// fraction of the object a receiver point sees, estimated from a few target points on the
// object, cosine-weighted at the receiver, tested with rays
//   - against the static world (Embree, brf_static_visibility): static receivers (atlas
//     texels) behind a wall get exactly 0;
//   - against the other dynamic objects' oriented boxes (brf_box_visibility, the GPU pass's
//     brf_phi.comp.glsl does the same tests): a crate behind another crate gets what passes
//     beside it.
// The result multiplies that (source, receiver point) pair's basis irradiance Phi, so it is
// evaluated only when the pair's Phi is (its pose or an occluder's changed).
//   const auto targets = gi::brf_visibility_targets(mesh);          // object space, once
//   gi::brf_static_visibility(world, world_targets, positions, normals, visibility);

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "brf/brf_runtime.h"

namespace gi {

class RayCaster;

/// How many target points stand for an object: its box centre and the 8 corners pulled
/// toward it (kBrfCornerPull of the half extents).
inline constexpr std::size_t kBrfVisibilityTargets = 9;
inline constexpr float kBrfCornerPull = 0.7f;

/// The object-space target points of an object whose box is `box` (brf_object_box).
std::array<glm::vec3, kBrfVisibilityTargets> brf_visibility_targets(const BrfBox& box);

/// Receiver point p (unit normal n) against targets (world space): sum over targets in front
/// of the tangent plane of cos(n, target - p) for those `visible` says are unblocked, over the
/// same sum for all of them; 0 when no target is in front. `visible(i, origin, target)` is
/// asked only for targets in front.
template <class Visible>
float brf_weighted_visibility(const glm::vec3& p, const glm::vec3& n, std::span<const glm::vec3> targets,
                              Visible&& visible);

/// out[j] = the fraction of `targets` (world space, one object) receiver j sees past the
/// static world `world` (cosine-weighted, brf_weighted_visibility); rays start off the
/// receiver's surface (offset_ray_origin) and stop at the target. Preconditions: positions,
/// normals and out have equal sizes.
void brf_static_visibility(const RayCaster& world, std::span<const glm::vec3> targets,
                           std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                           std::span<float> out);

/// True when the segment from a to b passes through no occluder's box (a, b in the space
/// BrfOccluder::to_occluder maps from).
bool brf_segment_clear(const glm::vec3& a, const glm::vec3& b, std::span<const BrfOccluder> occluders);

/// out[j] = the fraction of `targets` receiver j sees past `occluders` (cosine-weighted as
/// above; the segment test brf_segment_clear). Preconditions: sizes equal.
void brf_box_visibility(std::span<const BrfOccluder> occluders, std::span<const glm::vec3> targets,
                        std::span<const glm::vec3> positions, std::span<const glm::vec3> normals, std::span<float> out);

/// The form factor (cosine-weighted solid angle / pi) of an object's box (object space, placed
/// by `object_to_world`) seen from world point p with unit normal n: the share of p's
/// irradiance from a uniformly bright sky that the box blocks. Sum over the box faces p sees
/// of Lambert's polygon formula, each face clamped to [0, 1], the sum too; 1 inside the box.
/// What the static world's baked indirect light loses under and around a dynamic object
/// (BrfResult::static_occlusion).
float brf_box_form_factor(const BrfBox& box, const glm::mat4& object_to_world, const glm::vec3& p, const glm::vec3& n);

/// Contact (docs/brf.md, "Contact"): a receiver point p (unit normal n, both in the source's
/// object space) whose normal runs into the source's box within kBrfContactGap x the box's
/// mean half extent sees only the source's surface right in front of it, which the receiver
/// itself keeps dark: t / gap for a hit at distance t along n, 0 for a point inside the box,
/// 1 when n misses the box or hits it farther away. brf_basis_irradiance and brf_phi.comp.glsl
/// multiply Phi by it.
inline constexpr float kBrfContactGap = 0.25f;
float brf_contact_visibility(const BrfBox& box, const glm::vec3& p, const glm::vec3& n);

/// A bounding sphere in world space.
struct BrfSphere {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};
/// The sphere around `box` (object space) placed by `object_to_world` (uniform scale allowed).
BrfSphere brf_bounding_sphere(const BrfBox& box, const glm::mat4& object_to_world);

/// The objects that may stand between source `source` and receiver `receiver`: every other
/// object whose sphere comes within its radius + the larger of the pair's radii of the
/// segment between the pair's centres (every line from a receiver point to a source point
/// lies in that capsule). Ascending indices.
std::vector<std::uint32_t> brf_pair_occluders(std::span<const BrfSphere> spheres, std::size_t source,
                                              std::size_t receiver);

// ---------------------------------------------------------------------------------------

template <class Visible>
float brf_weighted_visibility(const glm::vec3& p, const glm::vec3& n, std::span<const glm::vec3> targets,
                              Visible&& visible) {
  float all = 0.0f, seen = 0.0f;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const glm::vec3 d = targets[i] - p;
    const float len = glm::length(d);
    if (!(len > 0.0f)) continue;
    const float c = glm::dot(n, d) / len;
    if (c <= 0.0f) continue;
    all += c;
    if (visible(i, p, targets[i])) seen += c;
  }
  return all > 0.0f ? seen / all : 0.0f;
}

}  // namespace gi
