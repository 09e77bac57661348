#pragma once
// The one BRDF of the project: glTF 2.0's metallic-roughness model (specification Appendix
// B), with the factors of KHR_materials_specular. The forward renderer's GLSL
// (engine/shaders/gltf_brdf.glsl, a line-by-line twin that a test keeps equal), the
// reference path tracer and the bakers' albedo folding all evaluate it from here.
//
//   material    = mix(dielectric_brdf, metal_brdf, metallic)
//   metal_brdf  = conductor_fresnel(f0 = baseColor, specular_brdf(alpha))
//   dielectric  = fresnel_mix(specularColor, ior 1.5, weight = specular, diffuse_brdf(baseColor),
//                             specular_brdf(alpha))
//               = (1 - specular * max(F)) * baseColor / pi + specular * F * specular_brdf
//   F           = f0 + (1 - f0) (1 - |V.H|)^5  (Schlick; dielectric f0 = min(0.04 specularColor, 1))
//   specular_brdf = D_GGX(alpha) * V_Smith(height-correlated), alpha = roughness^2
//
// Roughness is clamped to [kGltfMinRoughness, 1] everywhere (a mirror is a delta the
// renderer cannot sample). Energy: the metal lobe never reflects more than it receives;
// glTF's fresnel_mix does at grazing view angles for smooth, near-white dielectrics (the
// specification says so itself, Appendix B "Coupling Diffuse and Specular Reflection");
// docs/brdf.md tabulates it.
//
//   engine::GltfBrdf m = engine::gltf_brdf(base_color, metallic, roughness);
//   glm::vec3 f_cos = engine::gltf_eval_cos(m, n, v, l).sum();

#include <glm/glm.hpp>

namespace engine {

/// Roughness below this is raised to it (GGX alpha >= 0.045^2).
inline constexpr float kGltfMinRoughness = 0.045f;
/// Dielectric reflectance at normal incidence: ((1 - ior) / (1 + ior))^2 at ior 1.5.
inline constexpr float kGltfDielectricF0 = 0.04f;

/// The BRDF's parameters at one shading point (material factors times texture values).
struct GltfBrdf {
  glm::vec3 base_color{1.0f};    ///< Linear base colour.
  float metallic = 0.0f;         ///< In [0, 1].
  float alpha = 1.0f;            ///< GGX alpha = clamped roughness^2.
  float specular_weight = 1.0f;  ///< KHR_materials_specular specularFactor: 0 = pure Lambertian dielectric.
  glm::vec3 dielectric_f0{kGltfDielectricF0};  ///< min(0.04 x specularColorFactor, 1).
};

/// Builds the parameters from material factors, clamping them to their ranges.
GltfBrdf gltf_brdf(const glm::vec3& base_color, float metallic, float roughness, float specular_weight = 1.0f,
                   const glm::vec3& specular_color = glm::vec3(1.0f));

/// A pure Lambertian surface of albedo `albedo` (a dielectric with specular weight 0).
GltfBrdf gltf_lambertian(const glm::vec3& albedo);

/// GGX (Trowbridge-Reitz) normal distribution D(n.h).
float gltf_ggx_distribution(float n_dot_h, float alpha);
/// Height-correlated Smith visibility V = G2 / (4 n.l n.v) (Heitz 2014, eq. 99).
float gltf_smith_visibility(float n_dot_v, float n_dot_l, float alpha);
/// Schlick's (1 - |v.h|)^5, with v.h clamped to [0, 1].
float gltf_schlick_weight(float v_dot_h);

/// f(v, l) cos(theta_l), split into the (Fresnel-weighted) diffuse lobe and the specular
/// lobe. All vectors unit length; n on the side of v. Zero when l is below the horizon.
struct GltfBrdfValue {
  glm::vec3 diffuse{0.0f};
  glm::vec3 specular{0.0f};
  glm::vec3 sum() const { return diffuse + specular; }
};
GltfBrdfValue gltf_eval_cos(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l);

/// Weight of the diffuse lobe for the half-vector angle: 1 - specular * max_c(F_dielectric).
float gltf_diffuse_weight(const GltfBrdf& m, float v_dot_h);

/// Directional albedo at cos(theta_v) = n_dot_v: the radiance reflected towards v per unit
/// of uniform incident radiance, per lobe. This is also what a surface reflects of
/// irradiance E that arrives without direction information: L = E / pi x albedo.
/// Read from gltf_albedo_table() (bilinear, as the GLSL twin reads its texture).
GltfBrdfValue gltf_directional_albedo(const GltfBrdf& m, float n_dot_v);

/// Hemispherical (cosine-weighted mean of the directional) albedo per lobe: the fraction
/// of diffusely arriving light the surface reflects. The bakers fold every surface into a
/// diffuse reflector of albedo sum() (docs/brdf.md). Integrated at the material's own alpha.
GltfBrdfValue gltf_hemispherical_albedo(const GltfBrdf& m);

/// The three integrals behind the albedos, tabulated over cos(theta_v) and roughness:
///   a = integral of D V cos dl,  b = integral of (1 - v.h)^5 D V cos dl   (specular lobe),
///   p = integral of (1 - v.h)^5 cos / pi dl                                (diffuse weight).
/// Then specular albedo = f0 a + (1 - f0) b per Fresnel colour and the diffuse weight's mean
/// is 1 - specular (f0max + (1 - f0max) p). Computed once, by deterministic quadrature, on
/// first use (thread-safe). Node (i, j): cos_v = max((i / (N - 1))^2, kMinCos) (dense at
/// grazing angles, where the integrals change fastest), roughness = kGltfMinRoughness +
/// (1 - kGltfMinRoughness) j / (N - 1); interpolation is linear in sqrt(cos_v) and roughness.
struct GltfAlbedoTable {
  static constexpr int kSize = 32;
  static constexpr float kMinCos = 1e-4f;
  /// [j][i] = (a, b, p, 0) at roughness node j and cos node i (the GPU texture's layout).
  glm::vec4 node[kSize][kSize];
  /// Bilinear between nodes, coordinates clamped to the table.
  glm::vec4 sample(float n_dot_v, float roughness) const;
};
const GltfAlbedoTable& gltf_albedo_table();

/// The same three integrals at one point, by the table's quadrature (for tests and docs).
glm::vec4 gltf_albedo_integrals(float n_dot_v, float alpha);

}  // namespace engine
