#pragma once
// Step 1 of the texel gather (texel_gather.h): the direct irradiance at one texel by light
// sampling. Punctual lights take one shadow ray, the sun's disc, area lights and emissive
// triangles `samples` stratified samples each (unbiased).
//   gi::Pcg32 rng = gi::Pcg32::for_item(seed, stream);
//   const gi::DirectAt d = gi::direct_at(scene, p, n, face, 16, rng, &rays);

#include <cstdint>
#include <glm/glm.hpp>

#include "core/random.h"
#include "transport/static_scene.h"

namespace gi {

// Step 1 at one texel, light sampling only: `live`, every static light and the emissive
// triangles that stand for an area light (the renderer draws those lights); `unlit`, the
// emissive triangles no light stands for (the renderer draws no light of theirs).
struct DirectAt {
  glm::vec3 live{0.0f}, unlit{0.0f};
  /// Of live + unlit: the area lights' and the emissive triangles' light, which sampling
  /// estimates with noise (the rest, point / spot / directional lights and the sun's disc,
  /// takes a shadow ray or a few and is sharp).
  glm::vec3 sampled{0.0f};
};

/// Which lights direct_at samples.
enum class DirectLights {
  All,
  Punctual,  ///< Point, spot and directional lights and the sun's disc only (no area lights, no emitters).
};

/// At point p with shading normal n on a triangle facing `face`: shadow rays leave from
/// p offset along `face`, and light arriving below either normal counts for nothing.
/// `*rays` grows by the shadow rays cast.
DirectAt direct_at(const StaticBakeScene& scene, const glm::vec3& p, const glm::vec3& n, const glm::vec3& face,
                   int samples, Pcg32& rng, std::uint64_t* rays, DirectLights which = DirectLights::All);

}  // namespace gi
