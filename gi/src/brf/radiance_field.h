#pragma once
// Basis radiance fields (Iwasaki et al. §4.3): around a rigid object, sample points on
// concentric spheres record, for every PCA basis function Psi_i, the radiance arriving from
// the object when its surface shines with radiosity Psi_i (diffuse: radiance Psi_i / pi),
// projected onto spherical harmonics. At runtime the radiance the object sends to any point
// is interpolated from the nearest samples and weighted by the object's current weights.
// A glossy object (brdf_separation.h) has K = 1 + glossy terms channels per basis
// function: S_(k,i)(p, w) = h_k(-w) Psi_i at the hit (eq. 9 and §4.3), h_k in the hit's
// tangent frame (h_0 = 1/pi, the diffuse term).
//   auto field = gi::compute_basis_radiance_field(mesh, basis, {.spheres = 16}).value();
//   std::vector<float> c(field.basis_count * field.coefficient_count());
//   field.sample(receiver_point, c);   // object space

#include <engine/result.h>
#include <gi/progress.h>

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "brf/pca_basis.h"

namespace gi {

struct RadianceFieldSettings {
  int spheres = 16;                 ///< Concentric spheres.
  int face_resolution = 16;         ///< Points per sphere: 6 cube faces x resolution^2.
  int sh_bands = 3;                 ///< 3 (9 coefficients) or 4 (16).
  float inner_radius_scale = 1.0f;  ///< Innermost sphere at this x the bounding radius.
  float outer_radius_scale = 8.0f;  ///< Outermost; spheres are spaced geometrically between.
  int directions = 256;             ///< Rays per sample point for the projection.
  unsigned threads = 0;
  ProgressCallback progress;  ///< Fraction of the sample points done; false cancels.
};

struct BasisRadianceField {
  int spheres = 0;
  int face_resolution = 0;
  int sh_bands = 0;
  int basis_count = 0;
  int terms = 1;  ///< K: 1 + glossy terms.
  glm::vec3 centre{0.0f};
  float inner_radius = 0.0f;
  float outer_radius = 0.0f;
  /// [sphere][face][v][u][term][basis][coefficient], floats.
  std::vector<float> coefficients;

  int coefficient_count() const { return sh_bands * sh_bands; }
  /// Channels per sample point: (term, basis function) pairs, channel = k x basis_count + i.
  int channel_count() const { return terms * basis_count; }
  std::size_t bytes() const { return coefficients.size() * sizeof(float); }
  /// Radius of sphere s.
  float sphere_radius(int s) const;
  /// The basis radiance at object-space point p, SH coefficients per channel
  /// (out[channel * coefficient_count() + c]), interpolated over the 8 surrounding samples
  /// (bilinear on the cube face, linear in log radius of r^2 x coefficients). Inside the innermost sphere the
  /// innermost values are used; beyond the outermost they fall off as 1 / r^2 (the object
  /// subtends a smaller solid angle). Precondition: out.size() >= channel_count() x coefficients.
  void sample(const glm::vec3& p, std::span<float> out) const;
};

/// Errors: settings out of range, a basis that does not belong to the mesh, a basis trained
/// for other terms than `glossy` gives (nullptr: diffuse).
engine::Result<BasisRadianceField> compute_basis_radiance_field(const BrfMesh& mesh, const BrfBasis& basis,
                                                                const RadianceFieldSettings& settings,
                                                                const BrdfSeparation* glossy = nullptr);

}  // namespace gi
