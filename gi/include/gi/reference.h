#pragma once
// The reference path tracer: the ground truth every GI method is measured against.
// Unbiased path tracing of the renderer's BRDF (glTF's, engine/gltf_brdf.h) with next-event estimation
// to point, spot, directional and area lights and to emissive surfaces, multiple importance
// sampling (power heuristic) between light and BRDF sampling for emissive surfaces, and
// Russian roulette. Multithreaded and deterministic: every pixel or point draws from its
// own random stream, so results are bit-identical for any thread count.
//   auto img = gi::render_reference_image(scene, engine::find_camera(scene.registry), 256, 256, {.samples_per_pixel = 64});
//   engine::save_exr("reference.exr", img.value());
//
// What it does not do yet: textures (base colour, emissive, metallic-roughness factors only)
// and normal maps; area lights that have no emissive geometry are sampled by next-event
// estimation only (BRDF-sampled rays cannot hit them, so no MIS for those).

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <engine/entity.h>
#include <engine/image.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <gi/progress.h>

namespace gi {

struct ReferenceSettings {
  /// Samples per pixel (images) or per point (irradiance).
  int samples_per_pixel = 64;
  /// Indirect bounces: -1 unlimited (Russian roulette ends paths), 0 direct light only.
  int max_bounces = -1;
  /// Path vertex from which Russian roulette may end a path.
  int russian_roulette_start = 3;
  std::uint64_t seed = 1;
  /// Worker threads; 0: all hardware threads. The result does not depend on it.
  unsigned threads = 0;
  /// false: every camera sample passes through the pixel centre (no anti-aliasing), which is
  /// what a rasterizer does; used to compare with the renderer pixel by pixel.
  bool jitter_pixels = true;
  ProgressCallback progress;
};

/// Linear radiance, W/(m^2 sr), seen from `camera` (an entity with Camera and
/// WorldTransform) at width x height (rows top to bottom; alpha 1). Errors: no such camera,
/// bad sizes or settings, malformed geometry, cancellation.
engine::Result<engine::ImageRgbaF> render_reference_image(const engine::Scene& scene, engine::Entity camera, int width,
                                                          int height, const ReferenceSettings& settings);

/// A receiver of irradiance: a point on a surface and the unit normal of its lit side.
struct SurfacePoint {
  glm::vec3 position_m{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
};

/// Irradiance, W/m^2 per RGB channel: `direct` arrives straight from lights and emissive
/// surfaces, `indirect` after one or more reflections (total = direct + indirect).
struct IrradianceEstimate {
  std::vector<glm::vec3> direct;
  std::vector<glm::vec3> indirect;
};

/// Estimates the irradiance at each point (samples_per_pixel samples each). This is the
/// ground truth of light-atlas texels.
engine::Result<IrradianceEstimate> reference_irradiance(const engine::Scene& scene, std::span<const SurfacePoint> points,
                                                         const ReferenceSettings& settings);

}  // namespace gi
