#pragma once
// The separable approximation of a glossy BRDF (Iwasaki et al. §4.1, eq. 6, after Kautz and
// McCool 1999): f_r(w_in, w_out) ~ sum_k g_k(w_in) h_k(w_out), both in the surface's local
// frame (z = normal). The incoming side g_k weighs the light a vertex receives into K
// per-vertex values L_k (eq. 8), which the PCA basis fits like diffuse radiosity; the
// outgoing side h_k gives the radiance those values send in each direction (eq. 9).
//
// The glossy lobe (GGX with height-correlated Smith visibility and Schlick Fresnel, the
// renderer's and the path tracer's, raytrace/reference_brdf.h) is sampled on an R x R
// octahedral map of the hemisphere. The matrix M_oi = f(w_i, w_o) cos_i cos_o
// sqrt(Omega_o Omega_i) (Omega: the cells' solid angles) is decomposed by SVD, and the first
// K singular triplets give g_k = sqrt(s_k) v_k / (sqrt(Omega) cos_i) and h_k = sqrt(s_k) u_k
// / (sqrt(Omega) cos_o). The cosines weigh the error as it reaches the light: f cos_i is what
// multiplies incoming radiance, and cos_o keeps the near-grazing corner of the lobe (where
// Smith's visibility makes f large but little projected light leaves) from dominating the
// decomposition. `relative_error` is the weighted L2 error of the truncation,
// sqrt(sum_{k >= K} s_k^2 / sum s_k^2). A separable (w_in, w_out) approximation suits
// low-frequency lobes only (the paper's "low-frequency glossy BRDFs"): for GGX with
// alpha = 0.5 four terms leave 0.55, for alpha = 0.8 0.29 (BrfGlossySeparation tests).
//
// An isotropic lobe's singular vectors come in azimuthal pairs (cos m phi, sin m phi) with
// equal singular values; cutting a pair in half would make the result depend on the
// tangent frame, so K grows by one when the next singular value equals the last kept one.
// The diffuse part of a material is not in here: it is its own exact term (g = 1, h = 1/pi).
//   auto sep = gi::separate_glossy_brdf({.f0 = 0.04f, .alpha = 0.25f}, {.terms = 4}).value();
//   float f = sep.eval(w_in_local, w_out_local);

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>

#include "brf/spherical_harmonics.h"

namespace gi {

/// Most glossy terms a separation keeps (K <= 1 + this with the diffuse term).
inline constexpr int kMaxGlossyTerms = 15;

struct GlossyLobe {
  float f0 = 0.04f;     ///< Specular reflectance at normal incidence (a scalar: the shape).
  float alpha = 0.25f;  ///< GGX alpha = roughness^2.
};

struct BrdfSeparationSettings {
  int terms = 4;        ///< K wanted (a split azimuthal pair adds one).
  int resolution = 24;  ///< R: the hemisphere table is R x R directions.
};

struct BrdfSeparation {
  GlossyLobe lobe;
  int terms = 0;
  int resolution = 0;
  std::vector<float> g, h;             ///< [k * R * R + cell], cells row-major over (v, u).
  std::vector<float> lobe_sh;          ///< [k * 16 + c]: SH of g_k(w) max(0, w.z), local frame.
  std::vector<float> singular_values;  ///< All of them, descending.
  float relative_error = 0.0f;

  float g_at(int k, const glm::vec3& local) const;  ///< Bilinear in the table; w below the horizon: its edge.
  float h_at(int k, const glm::vec3& local) const;
  /// sum_k g_k(w_in) h_k(w_out), local unit directions.
  float eval(const glm::vec3& w_in, const glm::vec3& w_out) const;
  /// h rescaled per outgoing cell (same layout) so that uniform incoming light reflects the
  /// lobe's exact directional albedo: sum_k h_k(w_o) int g_k cos = int f cos. The truncated
  /// separation alone does not keep it (roughness 0.5, 4 terms: 1.17x at 18 degrees off the
  /// normal, 0.81x at 49), which showed as a view-dependence about twice the path tracer's on
  /// screen. Scales are clamped to [1/4, 4]; cells whose separated albedo is <= 0 keep h.
  std::vector<float> albedo_corrected_h() const;
  std::span<const float> lobe_coefficients(int k) const {
    return std::span<const float>(lobe_sh).subspan(static_cast<std::size_t>(k) * kMaxShCoefficients,
                                                   kMaxShCoefficients);
  }
};

/// Errors: alpha or f0 out of (0, 1], terms outside [1, kMaxGlossyTerms], resolution outside [4, 64].
engine::Result<BrdfSeparation> separate_glossy_brdf(const GlossyLobe& lobe, const BrdfSeparationSettings& settings);

/// The glossy lobe itself (specular part only, f0 as given), local unit directions.
float glossy_lobe_brdf(const GlossyLobe& lobe, const glm::vec3& w_in, const glm::vec3& w_out);

/// The local frame of a surface point with unit normal n: columns tangent, bitangent, n.
/// Always built from an object-space normal, so the frame turns with the object.
glm::mat3 brf_tangent_frame(const glm::vec3& n);

/// Octahedral map of the upper hemisphere onto [-1, 1]^2 and back (local frame, z up).
glm::vec2 hemisphere_to_square(const glm::vec3& w);
glm::vec3 square_to_hemisphere(const glm::vec2& s);

}  // namespace gi
