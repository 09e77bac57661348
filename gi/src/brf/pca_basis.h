#pragma once
// The PCA basis of a rigid object's reflected light (Iwasaki, Dobashi, Yoshimoto, Nishita,
// "Precomputed radiance transfer for dynamic scenes taking into account light
// interreflection", §4.2 and §5.2). N_light point lights around the object each give a
// distribution of reflected light over its vertices (with self-shadowing); their mean and
// the first N-1 principal components (SVD of the centred matrix C) are the N basis
// functions Psi_0..Psi_{N-1} (stored orthonormalized: the same span, so the same fits, with
// A = I up to rounding whatever the object's scale). At runtime any distribution L over the vertices is fitted by
// least squares, w = A^-1 b with A_mn = sum_j Psi_m Psi_n and b_m = sum_j Psi_m L (eq. 14);
// A^-1 is precomputed here.
//   gi::BrfBasis basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = 16}).value();
//   std::vector<float> w = basis.fit(radiosity);   // one channel
//
// Ill-conditioning: a flat or very simple object yields fewer independent distributions than
// asked for (C is rank-deficient). Principal components whose singular value is below
// `rank_tolerance` x the largest are dropped (so N may come out smaller, reported in
// `basis_count`), and A^-1 is a pseudo-inverse that ignores eigenvalues of A below
// `rank_tolerance^2` x the largest, so weights stay finite and bounded (condition number
// reported); eigenvalues of A below lambda_max / max_condition are ignored as well, so the
// single-precision runtime fit cannot amplify rounding.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>

namespace gi {

/// One rigid object in its own (object) space.
struct BrfMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  ///< Unit, one per position.
  std::vector<std::uint32_t> indices;
  std::vector<float> reflectance;  ///< Per vertex (luminance of the albedo); empty: 1.
};

struct PcaBasisSettings {
  int lights = 256;                 ///< N_light point lights around the bounding sphere.
  int basis = 16;                   ///< N, the mean included.
  float light_radius_scale = 1.5f;  ///< Lights at this x the bounding radius (1: on the sphere).
  float rank_tolerance = 1e-5f;     ///< Relative singular value below which components are dropped.
  /// Largest condition number of A kept by the pseudo-inverse: the runtime fits in single
  /// precision (GPU), where a condition of c loses about c x 6e-8 relative accuracy.
  double max_condition = 1e5;
};

struct BrfBasis {
  std::size_t vertex_count = 0;
  int terms = 1;                       ///< Distributions per vertex it was trained on: 1 + glossy terms.
  int basis_count = 0;                 ///< N actually kept (<= requested).
  std::vector<float> psi;              ///< Psi_i(x_j) at psi[i * vertex_count + j]; Psi_0 is the normalized mean.
  std::vector<float> a_inverse;        ///< N x N, row-major: the (pseudo-)inverse of A.
  std::vector<float> singular_values;  ///< Of the centred training matrix, descending.
  double condition = 1.0;              ///< Of A, over the eigenvalues kept.
  glm::vec3 centre{0.0f};              ///< Bounding sphere of the object.
  float radius = 0.0f;

  /// Least-squares weights of `values` (one per vertex): A^-1 b.
  std::vector<float> fit(std::span<const float> values) const;
  /// sum_i w_i Psi_i at every vertex.
  std::vector<float> reconstruct(std::span<const float> weights) const;
};

/// Reflected light of `mesh` at every vertex for a point light of unit intensity at `light`:
/// reflectance x cos / d^2 x visibility (self-shadowing by the mesh, `caster` built from it).
/// Precondition: caster traces exactly this mesh in the same space.
class RayCaster;
std::vector<float> point_light_response(const BrfMesh& mesh, const RayCaster& caster, const glm::vec3& light);

struct BrdfSeparation;
/// Errors: no triangles, sizes inconsistent, non-finite values, settings out of range.
/// `glossy`: the object's separated glossy lobe (nullptr: diffuse, K = 1).
engine::Result<BrfBasis> compute_pca_basis(const BrfMesh& mesh, const PcaBasisSettings& settings,
                                           const BrdfSeparation* glossy = nullptr);

}  // namespace gi
