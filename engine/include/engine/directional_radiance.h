#pragma once
// Specular reflection of incoming light stored per direction bin: a global set of N unit
// directions psi_k (a provider's choice, e.g. a spherical Fibonacci set) and, per surface
// point, the mean incoming radiance L_k (W/(m^2 sr), linear RGB) over the directions whose
// nearest usable bin is k (a bin is usable at normal n when n.psi_k > kDirectionalMinCos).
// The renderer's GLSL twin is engine/shaders/directional_radiance.glsl (a test keeps the two
// equal). A GI provider fills the bins (directional light maps, docs/integration.md).
//
// The glTF specular lobe (engine/gltf_brdf.h) is integrated against the bins by sampling it:
// kDirectionalLobeSamples fixed directions l_j (Hammersley points through GGX visible-normal
// sampling, Heitz 2018, around v), each reading the bin it falls in (the nearest usable
// direction, as the bake assigned light), weighted by f cos / pdf without Fresnel = G2/G1:
//   L_spec = albedo_spec(n.v, alpha) x sum_j w_j L_bin(l_j) / sum_j w_j
// This is sum_k L_k x (the lobe's share falling into bin k): the sum over Omega with each
// bin's solid angle, the share estimated by the samples. The lobe's alpha is widened by half
// a bin's angular radius, a = sqrt(alpha^2 + (0.5 a_bin)^2) (a_bin = directional_bin_alpha(N)),
// so that a sharp lobe does not jump from one bin to the next as the view moves; and the
// weights are normalized to the lobe's directional albedo at the material's own alpha (the
// table gltf_directional_albedo reads), so uniform incoming radiance L gives exactly L x
// albedo_spec: what the direction-less irradiance E = pi L gives through E/pi x albedo.
// Fresnel is taken from the albedo table (its variation across the lobe is not resolved).
//   glm::vec3 s = engine::directional_specular(brdf, n, v, dirs, radiance);

#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include <engine/gltf_brdf.h>

namespace engine {

/// Bins with n.psi_k at or below this hold no light at normal n (their light went to the
/// nearest usable bin).
inline constexpr float kDirectionalMinCos = 0.1f;

/// Lobe samples per evaluation (the GLSL twin uses the same points).
inline constexpr int kDirectionalLobeSamples = 8;
/// The lobe is widened by this fraction of a bin's angular radius (see above).
inline constexpr float kDirectionalLobeWidening = 0.5f;

/// The GGX alpha of one bin's angular radius for N bins over the sphere: a cap of solid
/// angle 4 pi / N has radius theta_b = acos(1 - 2/N); the half vector moves by half the
/// reflected direction's angle, so a_bin = tan(theta_b / 2).
float directional_bin_alpha(int bin_count);

/// Sample point j of kDirectionalLobeSamples in [0, 1)^2 (Hammersley).
glm::vec2 directional_lobe_sample_point(int j);

/// The bin a direction l falls in at normal n: the nearest direction with n.psi >
/// kDirectionalMinCos; -1 when none is usable.
int directional_bin_of(std::span<const glm::vec3> directions, const glm::vec3& n, const glm::vec3& l);

/// L_spec above. `directions` (unit) and `radiance` have the same size; n and v unit, v on
/// the side of n. Returns 0 when no bin is usable.
glm::vec3 directional_specular(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                               std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance);

}  // namespace engine
