#pragma once
// The reference path tracer's view of the one BRDF (engine/gltf_brdf.h, glTF 2.0's, as the
// renderer shades): evaluation is engine::gltf_eval_cos; this adds sampling. The diffuse
// lobe is sampled by cosine, the GGX lobe by its distribution of visible normals (Heitz
// 2018, "Sampling the GGX Distribution of Visible Normals"), the lobe chosen in proportion
// to the two lobes' directional albedos at wo; pdf() is the mixture's.
// Directions are unit vectors pointing away from the surface (wo to the viewer, wi to the light).
//   gi::ReferenceBrdf f{.normal = n, .material = engine::gltf_brdf(base_color, 0.0f, 0.5f)};
//   glm::vec3 fcos = f.eval_cos(wo, wi);

#include <glm/glm.hpp>

#include <engine/gltf_brdf.h>

namespace gi {

struct BrdfSample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};  ///< f cos(theta_i) / pdf.
  float pdf = 0.0f;        ///< Solid-angle density of wi (the mixture's).
};

struct ReferenceBrdf {
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  ///< Unit shading normal on the side wo lies.
  engine::GltfBrdf material;           ///< The glTF BRDF's parameters at this point.

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

/// A frame (t, b, n) around a unit vector n (Duff et al. 2017, "Building an Orthonormal
/// Basis, Revisited").
void orthonormal_basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b);

/// Cosine-weighted direction around unit n from two uniform numbers; pdf = cos / pi.
glm::vec3 sample_cosine_hemisphere(const glm::vec3& n, float u1, float u2);

/// A direction uniform over the solid angle of the cone of half-angle acos(cos_max) around
/// unit `axis` (a light's disc), from two uniform numbers in [0, 1).
glm::vec3 sample_cone(const glm::vec3& axis, float cos_max, float u1, float u2);

}  // namespace gi
