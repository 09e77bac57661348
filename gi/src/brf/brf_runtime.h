#pragma once
// The per-frame side of basis radiance fields on the CPU (Iwasaki et al. §5): rigid objects
// with their precomputed basis and field, placed by world transforms. Each update:
//   1. direct light at every object's vertices (point and spot lights, shadowed by all the
//      objects);
//   2. weights w = A^-1 b of each object's reflected light (eq. 14, per RGB channel);
//   3. basis irradiance at every receiver vertex from every other source object: the
//      source's field sampled at the vertex in the source's object space, dotted with the
//      receiver normal's clamped-cosine lobe in that same space (rotating the zonal lobe into
//      the source frame is the SH rotation of eq. 13 done on the receiver side);
//      bounce radiosity B = albedo x sum_i w_i Phi_i (eq. 12);
//   4. steps 2-3 again with B as the light, for more bounces.
// Pairs whose bound contribution I_c (§5.4) is below a threshold are skipped.
//   gi::BrfScene s; s.objects.push_back({&mesh, &basis, &field, transform, albedo});
//   gi::BrfResult r = gi::update_brf(s, lights, {.bounces = 3});
//   // r.indirect[object][vertex]: interreflected irradiance (W/m^2, RGB)

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "brf/pca_basis.h"
#include "brf/radiance_field.h"
#include "light_atlas/point_emitters.h"

namespace gi {

struct BrfObject {
  const BrfMesh* mesh = nullptr;
  const BrfBasis* basis = nullptr;
  const BasisRadianceField* field = nullptr;
  glm::mat4 object_to_world{1.0f};  ///< Rigid (rotation + translation; uniform scale allowed).
  glm::vec3 albedo{0.8f};           ///< Diffuse albedo.
};

struct BrfUpdateSettings {
  int bounces = 3;
  /// Skip a (source, receiver) pair when the source's bound irradiance at the receiver's
  /// bounding-sphere centre is below this fraction of the largest pair's.
  float cull_threshold = 1e-3f;
};

struct BrfResult {
  std::vector<std::vector<glm::vec3>> direct;    ///< [object][vertex] direct irradiance.
  std::vector<std::vector<glm::vec3>> indirect;  ///< [object][vertex] interreflected irradiance.
  std::size_t pairs_evaluated = 0;
  std::size_t pairs_culled = 0;
};

/// Preconditions: every object's mesh, basis and field belong together; lights are point or
/// spot emitters (PointEmitter::Kind::Punctual) in world space.
BrfResult update_brf(std::span<const BrfObject> objects, std::span<const PointEmitter> lights,
                     const BrfUpdateSettings& settings);

}  // namespace gi
