#pragma once
// The per-frame side of basis radiance fields on the CPU (Iwasaki et al. §5): rigid objects
// with their precomputed basis and field, placed by world transforms. A frame is
//   1. direct light at every object's vertices (point and spot lights, shadowed by all the
//      objects and the static world): brf_direct_light();
//   2. brf_interreflect(), the CPU twin of the GPU pass (brf_gpu_pass.h), from the light
//      arriving from outside the objects (direct + the static world's indirect light):
//      a. weights w = A^-1 b of each object's reflected light (eq. 14, per RGB channel);
//      b. the basis irradiance Phi_sr,i(x_j) of every (source s, receiver r) pair: the
//         source's field sampled at receiver vertex x_j in the source's object space, dotted
//         with the receiver normal's clamped-cosine lobe in that same space (rotating the
//         zonal lobe into the source frame is the SH rotation of eq. 13 done on the receiver
//         side). It depends on the pair's relative pose only, so it is computed once per
//         frame and shared by all bounces (and the GPU pass keeps it while the pose holds);
//      c. per bounce: E_r(x_j) = sum_s max(0, sum_i w_s,i Phi_sr,i(x_j)), the bounce
//         radiosity B = albedo x E (eq. 12) is fitted again for the next bounce;
//      d. static receivers (points of the static world, e.g. light-atlas texels) inside a
//         source's outermost field sphere get that source's bounce from its total radiosity
//         albedo x (incoming + interreflected), times the fraction of the source they see
//         past the static world when BrfStaticReceivers::world is given.
// Pairs whose bound contribution I_c (§5.4) — the first bounce's irradiance at the
// receiver's centre, facing the source, summed over the channels in absolute value — is below `cull_threshold` x the
// largest pair's are skipped for the whole frame (brf_pair_culling).
//   std::vector<gi::BrfObject> objects{{&mesh, &basis, &field, transform, albedo}};
//   gi::BrfResult r = gi::update_brf(objects, lights, {.bounces = 3});
//   // r.indirect[object][vertex]: interreflected irradiance (W/m^2, RGB)
//
// Glossy objects (BrfObject::glossy, brdf_separation.h) carry K = 1 + glossy terms values
// per vertex wherever a diffuse one carries one, laid out [k x vertex_count + vertex]:
// k = 0 the irradiance E, k >= 1 the g_k-weighted irradiance E_k = int L g_k cos (eq. 8 and
// 11). Their radiance leaving a vertex is albedo E / pi + specular sum_k h_k(w_out) E_k
// (brf_outgoing_radiance). As a source, each term is fitted with the basis and the field
// has a channel per (term, basis function); as a receiver, Phi gets one row per receiver
// term: the clamped-cosine lobe for k = 0, for k >= 1 the SH projection of g_k cos in the
// vertex's tangent frame rotated into the source's space (ShRotation, eq. 13).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "brf/brdf_separation.h"
#include "brf/brf_model.h"
#include "brf/pca_basis.h"
#include "brf/radiance_field.h"
#include "transport/point_emitters.h"

namespace gi {

class RayCaster;
struct BrfLodPoints;  // brf_lod.h

/// One placed object: the model it draws (an index into the caller's models) and its state
/// this frame.
struct BrfInstance {
  std::uint32_t model = 0;
  glm::mat4 object_to_world{1.0f};  ///< Rigid (rotation + translation; uniform scale allowed).
  glm::vec3 albedo{0.8f};           ///< Diffuse albedo.
  glm::vec3 specular{1.0f};         ///< Glossy colour: f0 (RGB) / glossy->lobe.f0; unused for a diffuse model.
};

/// An instance with its model's parts resolved, as the CPU twin's functions take it
/// (brf_object() builds one; tests and tools may point at parts they hold themselves).
struct BrfObject {
  const BrfMesh* mesh = nullptr;
  const BrfBasis* basis = nullptr;
  const BasisRadianceField* field = nullptr;
  glm::mat4 object_to_world{1.0f};  ///< Rigid (rotation + translation; uniform scale allowed).
  glm::vec3 albedo{0.8f};           ///< Diffuse albedo.
  /// The separated glossy lobe (nullptr: diffuse). The basis and field were baked with it.
  const BrdfSeparation* glossy = nullptr;
  glm::vec3 specular{1.0f};  ///< Glossy colour: f0 (RGB) / glossy->lobe.f0.

  int terms() const { return field->terms; }
};

/// `instance` of `model` as the CPU twin takes it (pointing into `model`).
inline BrfObject brf_object(const BrfModel& model, const BrfInstance& instance) {
  return {&model.mesh,     &model.basis,        &model.field,     instance.object_to_world,
          instance.albedo, model.glossy_lobe(), instance.specular};
}

struct BrfUpdateSettings {
  int bounces = 3;
  /// Skip a (source, receiver) pair when its bound contribution I_c is below this fraction
  /// of the largest pair's (0: evaluate every pair).
  float cull_threshold = 1e-3f;
  /// Occlusion between the objects: a pair's basis irradiance is scaled, per receiver point,
  /// by the fraction of the source it sees past the boxes of the objects in between
  /// (brf_pair_occluders, brf_box_visibility). Off: light passes through objects.
  bool occlusion = true;
  /// A source's influence: its outermost field sphere (the reach its static receivers get
  /// its bounce in, d. above) times this. A pair whose receiver's bounding sphere lies wholly
  /// outside its source's influence is skipped without evaluating anything: a uniform grid
  /// over the objects finds the pairs inside (brf_pair_influence), so the pairs a frame
  /// touches grow with the objects' neighbours, not with n^2. 0 (or below, or not finite):
  /// no limit, every pair is a candidate.
  float influence_scale = 1.0f;
  /// Level of detail for distant pairs (brf_lod.h): a pair whose receiver lies at least this
  /// x the source's innermost field sphere from the source's field centre (brf_pair_far) gets
  /// Phi in full only at the receiver's representative vertices (brf_lod_points), interpolated
  /// to the others. Diffuse receivers only. 0 (or below, or not finite): off, every vertex
  /// exact. Default 5, chosen by the per-vertex error and cost table in docs/brf.md ("Level of
  /// detail"): the 30-crate grid p95 0.96% / max 3.9% vertex error at 3 and 5 alike, the crates
  /// room (stacked crates) p95 3.0% / max 7.8% at 5 against 5.4% / 27% at 3, same cost.
  float lod_distance = 5.0f;
  /// With the level of detail, far pairs also take the horizon and the visibility (contact,
  /// occluders) from the representative points: whole rows are interpolated and the other
  /// vertices evaluate nothing (faster; a face partly hidden from the source gets its
  /// representative points' mix). Off: every vertex its own horizon and visibility.
  bool lod_shared_visibility = false;
};

/// Points of the static world that take the objects' bounce (world space, unit normals).
struct BrfStaticReceivers {
  std::span<const glm::vec3> positions;
  std::span<const glm::vec3> normals;
  /// The static world (not the objects). When given, each source's bounce at a receiver is
  /// scaled by the fraction of the source the receiver sees past it (brf_static_visibility,
  /// brf_visibility.h): a receiver behind a wall gets exactly 0.
  const RayCaster* world = nullptr;
};

struct BrfResult {
  /// [object][k x vertex_count + vertex]: k = 0 irradiance, k >= 1 glossy terms (above).
  std::vector<std::vector<glm::vec3>> direct;    ///< Direct light (update_brf only).
  std::vector<std::vector<glm::vec3>> indirect;  ///< Interreflected light.
  std::vector<glm::vec3> static_irradiance;      ///< [static receiver] irradiance from all objects.
  /// [static receiver] the share of its baked indirect light the objects block, in [0, 1]: the
  /// sum over sources whose field holds it of the source box's form factor
  /// (brf_box_form_factor) x its visibility, clamped. The world's light there is
  /// baked x (1 - static_occlusion) + static_irradiance.
  std::vector<float> static_occlusion;
  std::size_t pairs_evaluated = 0;
  std::size_t pairs_culled = 0;
  std::size_t pairs_lod = 0;  ///< Evaluated pairs that used the level of detail (brf_lod.h).
};

/// Per-vertex world-space positions and unit normals of an object; for a glossy object also
/// the tangent frames (columns t, b, n in world space, from the object-space normals).
struct BrfWorldVertices {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::mat3> frames;
};
BrfWorldVertices brf_world_vertices(const BrfObject& object);

/// Weights (per RGB channel, terms x basis_count each, [k x basis_count + i]) of per-vertex
/// values over an object, `radiosity` holding terms x vertex_count values ([k x V + j]).
std::array<std::vector<float>, 3> brf_fit_rgb(const BrfBasis& basis, std::span<const glm::vec3> radiosity);

/// An object's axis-aligned bounding box in its own space.
struct BrfBox {
  glm::vec3 lo, hi;
};
BrfBox brf_object_box(const BrfMesh& mesh);

/// A dynamic object standing in the way of a (source, receiver) pair, as its box: `box` in its
/// own object space, `to_occluder` maps the space the test runs in (the source's object space
/// in brf_basis_irradiance) into it.
struct BrfOccluder {
  BrfBox box;
  glm::mat4 to_occluder{1.0f};
};

/// Where an object (its box, object space) lies relative to the tangent plane of a receiver
/// point p with unit normal n (object space): wholly behind it (no light can arrive), wholly
/// in front (the unclamped cosine is exact), or straddling it.
enum class BrfHorizon : std::uint8_t { Behind, InFront, Straddling };
BrfHorizon brf_horizon(const BrfBox& box, const glm::vec3& p, const glm::vec3& n);

/// The basis irradiance at world points p_j (unit normals n_j) from `source`'s field:
/// out[(j * K_r + k') * C + c] = Phi_(k',c)(p_j), C = source's channel_count(), 0 where the
/// source is behind the receiver's tangent plane. For k' = 0 the irradiance lobe: the
/// unclamped cosine where the source is wholly in front (brf_horizon), else the clamped
/// cosine; for k' >= 1 (a glossy receiver: `receiver_glossy` and world `frames` given,
/// K_r = 1 + its terms) the projection of g_k' cos rotated from the vertex's frame. out is resized.
/// With `occluders` (boxes of other objects, to_occluder from the source's object space), each
/// point's rows are scaled by the fraction of the source it sees past them
/// (brf_box_visibility, brf_visibility.h; the V of eq. 12-13 taken out of the integral).
/// With `lod` (a diffuse receiver's table, brf_lod.h, for its positions), the field is
/// sampled only at its representative points and interpolated (brf_lod_interpolate), each
/// vertex scaled by its own visibility, or with `lod_shared_visibility` whole rows
/// (visibility included) interpolated from the points'.
void brf_basis_irradiance(const BrfObject& source, std::span<const glm::vec3> positions,
                          std::span<const glm::vec3> normals, std::vector<float>& out,
                          const BrdfSeparation* receiver_glossy = nullptr, std::span<const glm::mat3> frames = {},
                          std::span<const BrfOccluder> occluders = {}, const BrfLodPoints* lod = nullptr,
                          bool lod_shared_visibility = false);

/// One bounce of one pair (step c): out[k x V + j] += sum_c w[rgb][c] x phi[(j K_r + k) C + c]
/// (clamped at 0 for k = 0), phi as brf_basis_irradiance writes it (C = `channels`, K_r =
/// `receiver_terms`, V = out.size() / K_r), w the source's fitted weights per colour.
void brf_gather(std::span<const float> phi, std::size_t channels, std::size_t receiver_terms,
                const std::array<std::vector<float>, 3>& w, std::span<glm::vec3> out);

/// Radiance (W/(m^2 sr), RGB) leaving vertex j of `object` toward world direction w_out,
/// from its per-vertex values `light` ([k x V + j], incoming light of all kinds summed).
glm::vec3 brf_outgoing_radiance(const BrfObject& object, const BrfWorldVertices& vertices,
                                std::span<const glm::vec3> light, std::size_t j, const glm::vec3& w_out);

/// Pair culling (§5.4): culled[s * n + r] != 0 when the bound irradiance of source s at
/// receiver r's centre (facing s, weights `weights[s]`; sum over channels of |w Phi|, so
/// terms of opposite sign cannot cancel) is at most threshold x the largest pair's. The diagonal is always culled,
/// and so are the pairs outside each other's influence (brf_pair_influence with
/// `influence_scale`), whose bounds are not evaluated (the largest is over the pairs inside).
/// threshold <= 0: no bound is evaluated, only the influence culls.
std::vector<std::uint8_t> brf_pair_culling(std::span<const BrfObject> objects,
                                           std::span<const std::array<std::vector<float>, 3>> weights, float threshold,
                                           float influence_scale = 0.0f);

/// The pairs outside each other's influence (BrfUpdateSettings::influence_scale):
/// outside[s * n + r] != 0 when receiver r's bounding sphere (brf_bounding_sphere) lies wholly
/// outside source s's outermost field sphere (world space) x `influence_scale`, and on the
/// diagonal. The others are found through a uniform grid of the receivers' centres (cell: the
/// largest reach), O(n + candidate pairs) sphere tests; `influence_scale` <= 0 or not finite:
/// only the diagonal. `candidates` (optional): the pairs inside, s != r.
std::vector<std::uint8_t> brf_pair_influence(std::span<const BrfObject> objects, float influence_scale,
                                             std::size_t* candidates = nullptr);

/// Direct irradiance at every object's vertices from point/spot emitters (world space),
/// shadowed by all the objects and, when given, by `world` (the static scene).
std::vector<std::vector<glm::vec3>> brf_direct_light(std::span<const BrfObject> objects,
                                                     std::span<const PointEmitter> lights, const RayCaster* world);

/// Steps 2a-2d from `incoming[object][k x V + vertex]`, the light arriving from outside the
/// objects (a diffuse object: its irradiance only). `direct` is left empty. Preconditions: sizes match the meshes;
/// receiver spans have equal sizes.
BrfResult brf_interreflect(std::span<const BrfObject> objects, std::span<const std::vector<glm::vec3>> incoming,
                           const BrfUpdateSettings& settings, const BrfStaticReceivers& receivers = {});

/// How far an approximate interreflection (the level of detail, brf_lod.h) is from the exact
/// one, per vertex: each vertex's relative error of its interreflected irradiance (`indirect`,
/// RGB length), the denominator floored at 1% of the mean exact vertex irradiance (vertices
/// facing away from every neighbour get almost nothing). The largest and the 95th percentile;
/// docs/brf.md's level-of-detail table and its tests measure with it. Same shapes required.
struct BrfVertexError {
  double max = 0.0;
  double p95 = 0.0;
};
BrfVertexError brf_vertex_error(const BrfResult& approx, const BrfResult& exact);

/// Direct light (objects only, no world) then brf_interreflect; `direct` is filled.
/// Preconditions: every object's mesh, basis and field belong together; lights are point or
/// spot emitters (PointEmitter::Kind::Punctual) in world space.
BrfResult update_brf(std::span<const BrfObject> objects, std::span<const PointEmitter> lights,
                     const BrfUpdateSettings& settings);

}  // namespace gi
