#pragma once
// The BRDF of the reference path tracer: exactly the renderer's (engine/shaders/
// lighting_common.glsl): Lambert (diffuse albedo / pi) plus GGX with Smith height-correlated
// visibility and Schlick Fresnel. Sampling: the diffuse lobe by cosine, the GGX lobe by its
// distribution of visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible
// Normals"), the lobe chosen by its estimated reflectance; pdf() is the mixture's.
// Directions are unit vectors pointing away from the surface (wo to the viewer, wi to the light).
//   gi::ReferenceBrdf f{.normal = n, .diffuse_albedo = kd, .f0 = glm::vec3(0.04f), .alpha = 0.25f};
//   glm::vec3 fcos = f.eval_cos(wo, wi);

#include <glm/glm.hpp>

namespace gi {

struct BrdfSample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};  ///< f cos(theta_i) / pdf.
  float pdf = 0.0f;        ///< Solid-angle density of wi (the mixture's).
};

struct ReferenceBrdf {
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  ///< Unit shading normal on the side wo lies.
  glm::vec3 diffuse_albedo{0.0f};      ///< (1 - metallic) x base colour.
  glm::vec3 f0{0.04f};                 ///< Specular reflectance at normal incidence; 0: no GGX lobe.
  float alpha = 1.0f;                  ///< GGX alpha = roughness^2 (roughness clamped to >= 0.045 as the renderer does).

  /// f(wo, wi) cos(theta_i); zero below the horizon.
  glm::vec3 eval_cos(const glm::vec3& wo, const glm::vec3& wi) const;
  /// Density with which sample() picks wi.
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const;
  /// Samples wi from three uniform numbers in [0, 1). False when nothing is reflected
  /// (wi below the horizon or a zero BRDF).
  bool sample(const glm::vec3& wo, float u_lobe, float u1, float u2, BrdfSample& out) const;
  /// Probability of picking the GGX lobe for this wo.
  float specular_probability(const glm::vec3& wo) const;
};

/// The renderer's material-to-BRDF rule: diffuse = (1 - metallic) base, f0 = mix(0.04, base,
/// metallic), alpha = clamp(roughness, 0.045, 1)^2.
ReferenceBrdf brdf_from_material(const glm::vec3& base_color, float metallic, float roughness);

/// A frame (t, b, n) around a unit vector n (Duff et al. 2017, "Building an Orthonormal
/// Basis, Revisited").
void orthonormal_basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b);

/// Cosine-weighted direction around unit n from two uniform numbers; pdf = cos / pi.
glm::vec3 sample_cosine_hemisphere(const glm::vec3& n, float u1, float u2);

}  // namespace gi
