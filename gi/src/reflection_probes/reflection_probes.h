#pragma once
// Baked reflection probes (docs/reflection_probes.md): parallax-corrected cube maps of the
// static world's full radiance, prefiltered for GGX, for the sharp glossy surfaces below
// the directional light maps' roughness range and for dynamic objects. What every engine
// ships (Unity reflection probes, Unreal reflection captures, Godot's ReflectionProbe).
//   gi::ProbeAtlas atlas{&bake.layout, bake.width, bake.height, bake.irradiance, false};
//   auto probes = gi::bake_reflection_probes(input, atlas, gi::ReflectionProbeSettings{});
//   // probes->cubes[i].levels[m]: probe i's radiance for roughness m / (levels - 1)
//
// Steps:
//   1. Placement from the static world (probe_placement.h).
//   2. Capture: from each probe's centre, supersample x supersample rays per cube texel
//      through the static world. A ray that escapes sees the sky; a hit returns what the
//      renderer draws there: emission, the light atlas's irradiance E (indirect light, the
//      sky's and unlit emitters' direct light) reflected as E / pi x the directional albedo,
//      and the direct light of the static lights the atlas does not hold, through the glTF
//      BRDF, shadowed (the bake's emitters and materials: transport/point_emitters.h,
//      raytrace/material_lookup.h).
//   3. Prefilter into GGX mip levels (probe_cube.h, prefilter_ggx).
// Bit-identical for any thread count: every texel is computed on its own.

#include <engine/result.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "reflection_probes/probe_cube.h"
#include "reflection_probes/probe_placement.h"
#include "uv/atlas_layout.h"

namespace gi {

/// Static surfaces smoother than this go to the probes (the planner's rule, plan.cpp): below
/// the directional light maps' range, where a lobe narrower than their bins needs an image.
inline constexpr float kReflectionProbeMaxRoughness = 0.3f;

struct ReflectionProbeSettings {
  int resolution = 32;          ///< Face size of level 0 (a power of two, 4..512).
  int supersample = 2;          ///< Rays per texel side (1..8).
  int prefilter_samples = 128;  ///< GGX samples per prefiltered texel (>= 1).
  /// Static surfaces of roughness below this read the probes instead of the atlas's specular
  /// share (the planner's routing, plan.cpp); dynamic objects read them at any roughness.
  float max_roughness = kReflectionProbeMaxRoughness;
  int area_light_samples = 16;  ///< Points per area light for the static lights' direct light.
  ProbePlacementSettings placement;
  std::uint64_t seed = 1;
  unsigned threads = 0;  ///< 0: all hardware threads. The result does not depend on it.
};

/// The light the captures read on the static surfaces: a light-atlas bake as plain data.
struct ProbeAtlas {
  const AtlasLayout* layout = nullptr;  ///< The atlas's uv1 layout (one mesh per static instance).
  int width = 0;
  int height = 0;
  std::span<const glm::vec3> irradiance;  ///< W/m^2 per texel, row-major, dilated.
  bool holds_static_lights = false;       ///< The atlas holds the static lights' direct light too.
};

struct ReflectionProbeStats {
  std::uint64_t rays = 0;  ///< Camera and shadow rays of the captures.
  double place_seconds = 0.0;
  double capture_seconds = 0.0;
  double prefilter_seconds = 0.0;
  double total_seconds = 0.0;
};

struct ReflectionProbeSet {
  ReflectionProbeSettings settings;
  std::vector<ProbeVolume> probes;
  std::vector<ProbeCube> cubes;  ///< One per probe, full_mip_count(resolution) levels each.
  ReflectionProbeStats stats;
};

/// preview / medium / high: cube faces of 16^2 / 32^2 / 64^2 texels (docs/reflection_probes.md, "Costs").
engine::Result<ReflectionProbeSettings> reflection_probe_preset(std::string_view name);

/// Empty when the settings are usable, else what is wrong.
std::string check_reflection_probe_settings(const ReflectionProbeSettings& s);

/// Places, captures and prefilters the probes of the static instances of `input`. Errors:
/// invalid settings, no static geometry, an atlas whose layout does not match the input.
engine::Result<ReflectionProbeSet> bake_reflection_probes(const BakeInput& input, const ProbeAtlas& atlas,
                                                          const ReflectionProbeSettings& settings);

/// Re-captures and re-prefilters only the probes whose box meets [changed_min, changed_max]
/// (the bounds of what changed in the static world; `input` is the changed scene), keeping
/// the others: the update when one room's geometry or light changes. Returns the probes redone.
engine::Result<std::vector<std::size_t>> rebake_probes_touching(const BakeInput& input, const ProbeAtlas& atlas,
                                                                ReflectionProbeSet& set, const glm::vec3& changed_min,
                                                                const glm::vec3& changed_max);

/// How far (m) beyond its box a probe still holds a point in the forward pass's blend (the shader's
/// PROBE_BOX_MARGIN_M): the floor and walls the box was fitted to are inside it.
inline constexpr float kProbeBoxMarginM = 0.05f;

/// Probe `v`'s weight at p in the forward pass's blend (the shader's probe_weight x probe_visibility):
/// probe_blend_weight(v, p, kProbeBoxMarginM) x probe_visibility_weight(cube, v.centre, p), so where a
/// second viewpoint shares the box, a point one probe did not see takes the other's light.
float probe_visible_blend_weight(const ProbeVolume& v, const ProbeCube& cube, const glm::vec3& p);

/// The CPU twin of the forward pass's blend (reflection_probes.glsl, probe_specular, without the
/// directional albedo): the probes holding p, each read by probe_lobe_radiance with `samples` lobe
/// samples and the captured distances, weighted by probe_visible_blend_weight (by probe_blend_weight
/// alone when `visibility` is false) and normalized. False where no box holds p.
bool blended_probe_lobe(std::span<const ProbeVolume> probes, std::span<const ProbeCube> cubes,
                        const engine::GltfBrdf& brdf, const glm::vec3& p, const glm::vec3& n, const glm::vec3& v,
                        int samples, glm::vec3& out, bool visibility = true);

/// One prepared static world that captures probes anywhere: the oracle probes of the
/// accuracy diagnosis (docs/reflection_probes.md, "Where the corridor's error comes from": a
/// probe captured at the shaded point itself has no parallax error).
class ProbeCapturer {
 public:
  /// Errors as bake_reflection_probes'.
  static engine::Result<ProbeCapturer> make(const BakeInput& input, const ProbeAtlas& atlas,
                                            const ReflectionProbeSettings& settings);
  ProbeCapturer(ProbeCapturer&&) noexcept;
  ProbeCapturer& operator=(ProbeCapturer&&) noexcept;
  ~ProbeCapturer();

  /// A probe centred at `centre`, captured and prefiltered as the bake's probes are (the
  /// settings' resolution, supersample, prefilter samples); single-threaded.
  [[nodiscard]] ProbeCube bake_at(const glm::vec3& centre) const;
  /// What one capture ray from `origin` along unit `d` returns (the renderer's radiance where it
  /// lands); `distance` (optional): set to the distance to that surface, -1 when the ray escapes.
  [[nodiscard]] glm::vec3 radiance(const glm::vec3& origin, const glm::vec3& d, float* distance = nullptr) const;

 private:
  struct Impl;
  explicit ProbeCapturer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
