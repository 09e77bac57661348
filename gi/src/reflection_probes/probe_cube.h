#pragma once
// A reflection probe's cube map on the CPU: texel <-> direction in OpenGL's cube-map
// convention (so the levels upload to a GL cube map as they are), the box projection that
// gives the probe parallax, and the GGX prefilter into mip levels (docs/reflection_probes.md).
//   gi::ProbeCube cube = gi::make_probe_cube(32, 6);
//   cube.levels[0][gi::cube_texel_index(face, x, y, 32)] = radiance(gi::cube_texel_direction(face, x, y, 32));
//   gi::prefilter_ggx(cube, 128);   // levels 1.. from level 0: roughness m / (levels - 1)
//
// Faces in GL order +X, -X, +Y, -Y, +Z, -Z; texel (x, y) of a face of size s sits at
// (s, t) = ((x + 0.5) / s, (y + 0.5) / s), row y upwards in t, as glTexImage's rows are.

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

namespace engine {
struct GltfBrdf;
}

namespace gi {

class ThreadPool;

/// One probe's radiance (W/(m^2 sr), linear RGB) by direction, level m of size
/// max(size >> m, 1) holding the prefiltered radiance for roughness m / (levels - 1).
struct ProbeCube {
  int size = 0;                                ///< Face size of level 0, texels.
  std::vector<std::vector<glm::vec3>> levels;  ///< Per level: 6 faces x s x s, face-major, row-major.
  /// The distance (m) from the probe's centre to the surface the capture's rays met, per texel
  /// of a cube of face size cube_distance_size() (6 faces, row-major as the levels; the mean of
  /// the rays through the texel, kProbeFarDistance where all left the scene). Empty: box
  /// projection only.
  std::vector<float> distance;
  /// Face size of `distance`; 0: `size`. The bake stores kProbeDistanceScale x size.
  int distance_size = 0;
};

/// The capture's distances are stored at this multiple of level 0's face size: one texel per
/// 2 x 2 capture rays' quarter of a level-0 texel. At level 0's size, a wall beside an opening
/// that is about a texel wide (the demo corridor's 0.2 m jambs at 4 m, 32^2) had each of its
/// texels' mean mix the wall's and the far room's distances, and the parallax search met
/// phantom surfaces between them. docs/reflection_probes.md, "Distances finer than level 0".
inline constexpr int kProbeDistanceScale = 2;
/// The largest multiple of level 0's face size a file's distance cube may have (the reader's and
/// the set check's bound; twice kProbeDistanceScale, so a later finer scale still reads).
inline constexpr int kProbeMaxDistanceScale = 4;
/// Face size of a cube's distances (ProbeCube::distance_size, or level 0's).
inline int cube_distance_size(const ProbeCube& cube) { return cube.distance_size > 0 ? cube.distance_size : cube.size; }

/// The distance stored where a capture's rays met nothing (the sky).
inline constexpr float kProbeFarDistance = 1e4f;
/// The distance-corrected lookup's search (distance_corrected_direction): linear steps along
/// the ray, then secant steps; its distance scale's floor (m).
inline constexpr int kProbeSearchSteps = 12;
inline constexpr int kProbeSecantSteps = 3;
inline constexpr float kProbeMinSearchScaleM = 0.05f;
/// The distance-corrected lookup reads the box first: where the captured distance in the
/// direction of the ray's exit from the box is within this fraction of the exit's distance
/// from the probe, the probe saw the box's side there and the box's answer is taken (exact for
/// a room's walls, floor and ceiling); farther (an opening) the search goes on from the exit,
/// nearer (an object inside the box) it searches the whole ray. Negative: the search alone
/// (before issue 36's "box first"). docs/reflection_probes.md, "The box first".
inline constexpr float kProbeBoxSideTolerance = 0.1f;
/// The box first at an opening's rim: where the ray's exit from the box lies within a texel of
/// the rim, the bilinear mean distances there mix the side's distance with the far room's, and
/// a thin wall beside the opening (the demo corridor's 0.2 m jambs, a texel wide at 32^2) reads
/// as an opening. With this on, the side test also takes the nearest of the four distance texels
/// around the exit (the GPU's textureGather footprint): where those that saw the box's side there
/// weigh at least half of the bilinear mean (it lies nearer their distance than the others'), the
/// box's answer. docs/reflection_probes.md, "The opening's rim".
inline constexpr bool kProbeRimNearest = true;

/// An empty (black) cube: `levels` levels from `size` (a power of two; levels <= log2(size) + 1).
ProbeCube make_probe_cube(int size, int levels);
/// The largest useful level count for `size`: log2(size) + 1.
int full_mip_count(int size);
/// Face size of level `level`.
inline int cube_level_size(int size, int level) { return size >> level > 0 ? size >> level : 1; }

inline std::size_t cube_texel_index(int face, int x, int y, int s) {
  return (static_cast<std::size_t>(face) * static_cast<std::size_t>(s) + static_cast<std::size_t>(y)) *
             static_cast<std::size_t>(s) +
         static_cast<std::size_t>(x);
}

/// The unit direction through face coordinates (u, v) in [-1, 1] (u = 2s - 1, v = 2t - 1).
glm::vec3 cube_direction(int face, float u, float v);
/// The unit direction through the centre of texel (x, y) of a face of size s.
glm::vec3 cube_texel_direction(int face, int x, int y, int s);

/// Where direction `d` (not zero) meets the cube: its face and (u, v) in [-1, 1].
struct CubeCoordinate {
  int face = 0;
  float u = 0.0f, v = 0.0f;
};
CubeCoordinate cube_coordinate(const glm::vec3& d);

/// Solid angle (sr) of texel (x, y) of a face of size s; the 6 s^2 texels sum to 4 pi.
float cube_texel_solid_angle(int x, int y, int s);

/// Level `level` read in direction d, nearest texel.
glm::vec3 cube_lookup(const ProbeCube& cube, int level, const glm::vec3& d);

/// The cube read as the renderer's sampler reads it (textureLod with linear filtering):
/// bilinear within the face at each of the two levels around `lod` (clamped to the levels
/// held), linear between them. The GPU's seamless filtering blends across face edges; here
/// the face's edge texels are clamped (a difference within half a texel of an edge).
glm::vec3 cube_lookup_trilinear(const ProbeCube& cube, float lod, const glm::vec3& d);

/// Parallax correction (Lagarde and Zanuttini 2012, "Local image-based lighting with
/// parallax-corrected cubemaps"): the direction from the probe's centre to where the ray from
/// `p` along `r` (not zero) leaves the box [box_min, box_max] that stands for the room. `p`
/// must lie in the box (the caller blends only probes whose box holds the point); a point
/// outside is clamped onto it. The same formula as probe_direction() in the forward shader.
glm::vec3 box_projected_direction(const glm::vec3& p, const glm::vec3& r, const glm::vec3& centre,
                                  const glm::vec3& box_min, const glm::vec3& box_max);

/// The distance cube read bilinearly in direction d (edge texels clamped, as
/// cube_lookup_trilinear); kProbeFarDistance when the cube holds no distances.
float cube_distance_bilinear(const ProbeCube& cube, const glm::vec3& d);
/// The nearest and farthest of the four distance texels cube_distance_bilinear blends in
/// direction d (the GPU's textureGather footprint); kProbeFarDistance when the cube holds none.
struct CubeDistanceFootprint {
  float nearest = 0.0f, farthest = 0.0f;
};
CubeDistanceFootprint cube_distance_footprint(const ProbeCube& cube, const glm::vec3& d);

/// Parallax from the capture's own distances (a localized cube map searched as a distance
/// impostor: Szirmay-Kalos, Aszodi, Lazanyi and Premecz 2005, "Approximate ray-tracing on the
/// GPU with distance impostors"): the direction from the probe's centre to where the ray from
/// `p` along `r` meets the surface the probe saw, found by kProbeSearchSteps steps along the
/// ray for the first point behind that surface and kProbeSecantSteps secant steps. Light beyond
/// an opening of the box and objects inside it get their own depth, where a box puts both on
/// its sides. Falls back to box_projected_direction when `p` itself is hidden from the centre
/// or the cube has no distances, and to `r` when the ray leaves the scene. The same search as
/// probe_direction() in the forward shader.
/// First the box (kProbeBoxSideTolerance, `box_side_tolerance`): where the probe saw a surface
/// at the box's side in the direction of the ray's exit, the box's answer.
/// `rim_nearest`: kProbeRimNearest's side test at an opening's rim (off: the lookup before it).
glm::vec3 distance_corrected_direction(const ProbeCube& cube, const glm::vec3& p, const glm::vec3& r,
                                       const glm::vec3& centre, const glm::vec3& box_min, const glm::vec3& box_max,
                                       float box_side_tolerance = kProbeBoxSideTolerance,
                                       bool rim_nearest = kProbeRimNearest);

/// Levels the lobe's samples read finer where the probe saw beyond its box's side in the sample's
/// corrected direction (the captured distance more than kProbeBoxSideTolerance past the box): across
/// an opening the levels, prefiltered as if everything lay at one depth, blur the opening's lit
/// frame (near, at the box's side) into the far room's directions. docs/reflection_probes.md,
/// "Finer beyond the opening". 0: every sample at its lobe's level (the lookup before it).
inline constexpr float kProbeOpeningLevelBias = 1.0f;

/// Levels every lobe sample reads finer than its lobe's width asks for. A level holds its GGX
/// lobe on texels 2^m times level 0's, and the bilinear read widens it by about a texel; the
/// trilinear blend between two levels adds the wider one's tails instead of an intermediate width.
/// Both make a sample's read wider than its share of the lobe, which at grazing views carries a
/// lit frame's light into a dark opening (the demo corridor) and a lit wall's into the floor
/// behind an object (glossy_room). Measured 0, 0.25, 0.5 and 1 against the path tracer on both
/// scenes; docs/reflection_probes.md, "Half a level finer". 0: the lookup before it.
inline constexpr float kProbeLobeLevelBias = 0.5f;

/// A probe that did not see the shaded point (a second viewpoint in the same box sees it) weighs this
/// times its blend weight (probe_visibility_weight; the shader's PROBE_HIDDEN_WEIGHT).
inline constexpr float kProbeHiddenWeight = 1e-3f;
/// The slack (m) beyond kProbeBoxSideTolerance of the point's distance within which a captured distance
/// still counts as having seen the point (the shader's PROBE_SEES_SLACK_M).
inline constexpr float kProbeSeesSlackM = 0.05f;

/// Whether the probe captured at `centre` saw point p (docs/reflection_probes.md, "A second viewpoint where
/// the first is blocked"): 1 when its captured distance towards p (read bilinearly) is at least
/// |p - centre| (1 - kProbeBoxSideTolerance) - kProbeSeesSlackM, else kProbeHiddenWeight; 1 when the cube
/// holds no distances. The forward pass multiplies the probe's blend weight by it (the shader's
/// probe_visibility): where two probes share a box, a point one of them did not see takes the other's
/// light; a probe alone in its box keeps its share after the normalization.
float probe_visibility_weight(const ProbeCube& cube, const glm::vec3& centre, const glm::vec3& p);

/// The most lobe samples probe_lobe_radiance takes (the shader's PROBE_MAX_LOBE_SAMPLES).
inline constexpr int kProbeMaxLobeSamples = 64;
/// The lobe samples the runtime asks the forward pass for at a view along the normal
/// (IndirectLightFrame::reflection_probe_lobe_samples; 0: the split sum's single read;
/// docs/reflection_probes.md).
inline constexpr int kProbeLobeSamples = 4;
/// The most lobe samples the runtime lets a grazing view take (IndirectLightFrame::
/// reflection_probe_lobe_samples_max; probe_lobe_sample_count; docs/reflection_probes.md, "A
/// sample count that grows with the lobe's stretch").
inline constexpr int kProbeGrazingLobeSamples = 32;

/// The lobe samples a view at cos theta_v = `nv` takes: `samples` doubled while the count times
/// nv stays below `samples` (the lobe's extent along the reflection's plane grows about as
/// 1 / n.v), up to `most` (no more than kProbeMaxLobeSamples); a power-of-two multiple of `samples`,
/// so each count is a whole Hammersley set when `samples` is. `most` <= `samples`: `samples`
/// at every view. The shader's probe_lobe_count.
int probe_lobe_sample_count(int samples, int most, float nv);

/// The specular lobe at the actual view read from a prefiltered probe by filtered importance
/// sampling (Colbert and Krivanek 2007, "GPU-based importance sampling"): `samples` (1 ..
/// kProbeMaxLobeSamples) half vectors h_i drawn from GGX's distribution of visible normals at
/// v (Heitz 2018; the spherical-cap form of Dupuy and Benyoub 2023) at fixed Hammersley
/// points, each reflected direction l_i parallax-corrected (the captured distances, or the
/// box alone when `box_only`) and read trilinearly at the level prefiltered with the GGX lobe
/// as wide as the sample's share of the lobe: solid angle 1 / (samples pdf(l_i)), narrowed
/// across the reflection's plane by v.h, taken as 4 pi alpha_m^2 (lod = sqrt(alpha_m) x
/// (levels - 1), the prefilter's roughness per level). Unlike the split sum's lobe (prefiltered
/// around the reflection with n = v), these follow the lobe's stretch along the reflection's
/// plane and its off-specular shift at grazing views. Returned: the samples' radiance
/// weighted by the BRDF-sample weight F G2 / G1 (per channel), normalized by the weights' sum,
/// so the caller multiplies by the specular lobe's directional albedo as with the split sum
/// (the environment BRDF counted once; a constant cube returns that constant exactly). The
/// same lookup as probe_lobe() in engine/shaders/reflection_probes.glsl.
/// `chain` (optional, CPU only: the sweep's `lobe=fis_chain`, docs/reflection_probes.md): the
/// samples read this box-filtered chain of level 0 (box_filtered_chain) instead, at the level
/// whose texels span the sample's solid angle, + 1 (Colbert and Krivanek's own rule).
/// `box_side_tolerance`, `rim_nearest`: distance_corrected_direction's. `opening_level_bias`: the
/// levels a sample reads finer where the probe saw beyond its box's side (kProbeOpeningLevelBias).
/// `level_bias`: the levels every sample reads finer (kProbeLobeLevelBias).
glm::vec3 probe_lobe_radiance(const ProbeCube& cube, const engine::GltfBrdf& brdf, const glm::vec3& p,
                              const glm::vec3& n, const glm::vec3& v, int samples, const glm::vec3& centre,
                              const glm::vec3& box_min, const glm::vec3& box_max, bool box_only,
                              const ProbeCube* chain = nullptr, float box_side_tolerance = kProbeBoxSideTolerance,
                              bool rim_nearest = kProbeRimNearest, float opening_level_bias = kProbeOpeningLevelBias,
                              float level_bias = kProbeLobeLevelBias);

/// Level 0 of `cube` and its 2 x 2 box averages down to one texel per face, as a cube (what
/// the prefilter's samples read; its distances are level 0's).
ProbeCube box_filtered_chain(const ProbeCube& cube);

/// Fills levels 1.. of `cube` from level 0 with the split-sum's prefiltered radiance (Karis
/// 2013, "Real shading in Unreal Engine 4"): level m is the GGX lobe of alpha = r^2, r = m /
/// (levels - 1), around each texel's direction N with the view taken along N (n = v = r),
///   L_m(N) = sum_i L(l_i) (N.l_i) / sum_i (N.l_i),   l_i = reflect(-N, h_i),
/// h_i importance-sampled from D over `samples` points of a Hammersley set. Each sample reads
/// a box-downsampled copy of level 0 at the level whose texels span the sample's share of
/// the sphere (Colbert and Krivanek 2007, "GPU-based importance sampling"; + 1 level), so a
/// few samples see all of level 0's light and no texel sparkles. The weights sum to one per
/// texel: a constant map stays that constant at every level. Level 0 keeps the mirror image.
/// `pool` (optional) runs the texels of a level in parallel; the result does not depend on it.
void prefilter_ggx(ProbeCube& cube, int samples, ThreadPool* pool = nullptr);

}  // namespace gi
