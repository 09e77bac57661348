#pragma once
// Specular reflection of incoming light stored per direction bin: a global set of N unit
// directions psi_k (a provider's choice, e.g. a spherical Fibonacci set) and, per surface
// point, the mean incoming radiance L_k (W/(m^2 sr), linear RGB) over the directions whose
// nearest psi is psi_k (the paper's rule: every direction belongs to its nearest psi, also near
// the horizon, where the cells of the psi just below it keep their slivers above it; a bin
// with no part above the horizon holds 0). The renderer's GLSL twin is
// engine/shaders/directional_radiance.glsl (a test keeps the two equal). A GI provider fills
// the bins (directional light maps, docs/integration.md).
//
// The glTF specular lobe (engine/gltf_brdf.h) at the material's own alpha is integrated
// against the bins by sampling it: kDirectionalLobeSamples fixed directions l_j (Hammersley
// points through GGX visible-normal sampling, Heitz 2018, around v; 32: against the lobe
// integrated over the bins' cells, 16 left a rel RMSE of 0.19 on the demo corridor's grazing
// texels and 32 leave 0.10, docs/dlm.md "The grazing band's bias, split and removed"), each
// reading the bin it falls in, weighted by its f cos / pdf = F(v.h) G2 / G1
// per channel (a sample below the horizon weighs 0):
//   L_spec = albedo_spec(n.v, alpha) x sum_j w_j L_bin(l_j) / sum_j w_j
// This is sum_k L_k x (the lobe's share falling into bin k), the share estimated by the
// samples; scaled to the directional albedo (the table gltf_directional_albedo reads), so
// uniform incoming radiance L gives exactly L x albedo_spec: what the direction-less
// irradiance E = pi L gives through E/pi x albedo. The three grazing-view biases of the first
// version (horizon bins folded upwards, the lobe widened by half a bin, Fresnel-free weights
// renormalized to the Fresnel-weighted albedo) are tested in gi/tests/dlm/dlm_lookup_test.cpp.
//   glm::vec3 s = engine::directional_specular(brdf, n, v, dirs, radiance);
//
// Tangent-frame bins (a provider's option, docs/dlm.md "Tangent-frame bins in the renderer"):
// the directions are given in the tangent frame (t, b, n) of the surface's own normal n_bins
// (directional_tangent_frame, the one frame of the C++, the GLSL and the bake), usually on the
// hemisphere z > 0, so every bin lies above the horizon. A lobe sample l then reads the bin
// nearest (l.t, l.b, l.n_bins). n_bins is the geometric (vertex) normal the bins were baked at,
// not a normal-mapped one.
//   glm::vec3 s = engine::directional_specular(brdf, n, v, hemisphere_dirs, radiance, &n);

#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include <engine/gltf_brdf.h>

namespace engine {

/// Lobe samples per evaluation (the GLSL twin uses the same points).
inline constexpr int kDirectionalLobeSamples = 32;

/// Sample point j of kDirectionalLobeSamples in [0, 1)^2 (Hammersley).
glm::vec2 directional_lobe_sample_point(int j);

/// The frame (t, b, n) about unit n used for the lobe samples and for tangent-frame bins:
/// t = the x axis (the y axis when |n.x| > 0.9) made orthogonal to n, b = n x t.
void directional_tangent_frame(const glm::vec3& n, glm::vec3& t, glm::vec3& b);

/// The bin a direction l falls in: the nearest direction psi_k (the largest l.psi_k, the lowest
/// k among equals); -1 when there is none. The directions must be sorted by non-increasing z
/// (both of gi's sets are: Fibonacci points, uniform in z). The search starts at the index
/// where l.z would lie were the z uniform, and walks outwards on both sides until the z gap
/// alone bounds l.psi below the best found (l.psi <= l.z psi.z + |l.xy| |psi.xy|): a few z
/// rings instead of all N, the same bin as directional_bin_of_linear bit for bit (tested, and
/// the GLSL twin is the same code).
int directional_bin_of(std::span<const glm::vec3> directions, const glm::vec3& l);

/// The same by testing every direction (any order): the reference of the search above.
int directional_bin_of_linear(std::span<const glm::vec3> directions, const glm::vec3& l);

/// directional_specular with `samples` lobe samples instead of kDirectionalLobeSamples (the
/// same Hammersley construction; `samples` = kDirectionalLobeSamples is the renderer's lookup
/// exactly). For measurement: many samples integrate the lobe over the bins' cells almost
/// exactly (docs/dlm.md, "The grazing band's bias, split and removed"). With `kernel_radius`
/// > 0 (radians) a sample reads the bins within that angle blended, weights l.psi_k - cos(radius)
/// (the nearest bin where none is): a smooth reading across the cells' edges, measured there.
glm::vec3 directional_specular_sampled(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                                       std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
                                       const glm::vec3* bin_normal, int samples, float kernel_radius = 0.0f);

/// L_spec above. `directions` (unit) and `radiance` have the same size; n and v unit, v on
/// the side of n. Returns 0 without bins. With `bin_normal` the directions are tangent-frame
/// bins about *bin_normal (unit; directional_tangent_frame), else world-space ones. Directions
/// sorted by non-increasing z are searched as directional_bin_of does (the GPU's way: its
/// directions must be so sorted), others by testing each.
glm::vec3 directional_specular(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                               std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
                               const glm::vec3* bin_normal = nullptr);

}  // namespace engine
