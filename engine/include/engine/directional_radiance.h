#pragma once
// Specular reflection of incoming light stored per direction bin: a global set of N unit
// directions psi_k (a provider's choice, e.g. a spherical Fibonacci set) and, per surface
// point, the mean incoming radiance L_k (W/(m^2 sr), linear RGB) over the directions whose
// nearest usable bin is k (a bin is usable at normal n when n.psi_k > kDirectionalMinCos).
// The renderer's GLSL twin is engine/shaders/directional_radiance.glsl (a test keeps the two
// equal). A GI provider fills the bins (directional light maps, docs/integration.md).
//
// The glTF specular lobe (engine/gltf_brdf.h) is integrated against the bins as a sum over
// them, each bin weighted by the lobe at its direction:
//   w_k = D(n.h_k; a) V(n.v, n.psi_k; a) n.psi_k   (usable bins only)
//   L_spec = albedo_spec(n.v, alpha) x sum_k w_k L_k / sum_k w_k
// with the GGX alpha widened to the bins' angular resolution, a = sqrt(alpha^2 + a_bin^2),
// a_bin = directional_bin_alpha(N) (a lobe narrower than a bin would otherwise light up only
// when the reflection vector hits a bin direction), and the weights normalized to the
// lobe's directional albedo at the material's own alpha (the table gltf_directional_albedo
// reads), so uniform incoming radiance L gives exactly L x albedo_spec: what the
// direction-less irradiance E = pi L gives through E/pi x albedo. Fresnel is taken from the
// albedo table (its variation across the lobe is not resolved per bin).
//   glm::vec3 s = engine::directional_specular(brdf, n, v, dirs, radiance);

#include <span>

#include <glm/glm.hpp>

#include <engine/gltf_brdf.h>

namespace engine {

/// Bins with n.psi_k at or below this hold no light at normal n (their light went to the
/// nearest usable bin).
inline constexpr float kDirectionalMinCos = 0.1f;

/// The GGX alpha of one bin's angular radius for N bins over the sphere: a cap of solid
/// angle 4 pi / N has radius theta_b = acos(1 - 2/N); the half vector moves by half the
/// reflected direction's angle, so a_bin = tan(theta_b / 2).
float directional_bin_alpha(int bin_count);

/// L_spec above. `directions` (unit) and `radiance` have the same size; n and v unit, v on
/// the side of n. Returns 0 when no bin is usable.
glm::vec3 directional_specular(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                               std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance);

}  // namespace engine
