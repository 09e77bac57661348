#pragma once
// The reference path tracer: the ground truth every GI method is measured against.
// Unbiased path tracing of the renderer's BRDF (glTF's, engine/gltf_brdf.h) with next-event estimation
// to point, spot, directional and area lights and to emissive surfaces, multiple importance
// sampling (power heuristic) between light and BRDF sampling for emissive surfaces, and
// Russian roulette. Multithreaded and deterministic: every pixel or point draws from its
// own random stream, so results are bit-identical for any thread count.
//   auto img = gi::render_reference_image(scene, engine::find_camera(scene.registry), 256, 256, {.samples_per_pixel =
//   64}); engine::save_exr("reference.exr", img.value()); auto atlas =
//   gi::reference_atlas(gi::bake_input_from(scene), 32.0f, {.samples_per_pixel = 256});  // ground truth per texel
//
// What it does not do yet: textures (base colour, emissive, metallic-roughness factors only)
// and normal maps; area lights that have no emissive geometry are sampled by next-event
// estimation only (BRDF-sampled rays cannot hit them, so no MIS for those).

#include <engine/entity.h>
#include <engine/image.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <gi/bake_input.h>
#include <gi/progress.h>

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

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

/// A pinhole camera looking along its local -Z with +Y up.
struct ReferenceCamera {
  glm::mat4 camera_to_world{1.0f};
  float yfov_rad = 0.8f;  ///< Vertical field of view.
  float aspect = 0.0f;    ///< Width / height; 0: the image's.
};

/// Linear radiance, W/(m^2 sr), of `input` seen from `camera` at width x height (rows top to
/// bottom; alpha 1). Errors: bad sizes or settings, malformed geometry, cancellation.
engine::Result<engine::ImageRgbaF> render_reference_image(const BakeInput& input, const ReferenceCamera& camera,
                                                          int width, int height, const ReferenceSettings& settings);

/// The same for a live scene and one of its camera entities (Camera and WorldTransform).
/// Errors: also no such camera.
engine::Result<engine::ImageRgbaF> render_reference_image(const engine::Scene& scene, engine::Entity camera, int width,
                                                          int height, const ReferenceSettings& settings);

/// What the camera rays through the pixel centres hit first: the reference's geometry AOV,
/// to tell pixels apart by the place they show (world regions) and the background from the
/// level. Rows top to bottom, pixel (x, y) at y * width + x.
struct FirstHitImage {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> position_m;  ///< World-space point hit, metres; 0 where nothing is hit.
  std::vector<glm::vec3> normal;      ///< Unit normal of the triangle hit, facing the camera; 0 where none.
  std::vector<std::uint8_t> hit;      ///< 1: a surface; 0: the ray escapes (the sky, the background).
};

/// The first hits of the very rays render_reference_image traces with jitter_pixels = false
/// (one through each pixel's centre), the same geometry and camera conventions. `threads` as
/// in ReferenceSettings (the result does not depend on it). Errors: bad sizes or field of
/// view, malformed geometry.
engine::Result<FirstHitImage> reference_first_hits(const BakeInput& input, const ReferenceCamera& camera, int width,
                                                   int height, unsigned threads = 0);

/// A receiver of irradiance: a point on a surface and the unit normal of its lit side.
struct SurfacePoint {
  glm::vec3 position_m{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};  ///< Shading normal: the cosine's axis.
  /// Unit geometric normal of the surface under the point, on the lit side; zero: `normal`.
  /// Light from below the surface's own plane does not reach the point (the light atlas's
  /// gather does the same): a shading normal off the face no longer lets the point see the
  /// front of its own surface (docs/light_atlas.md, "Direct and indirect light").
  glm::vec3 face_normal{0.0f};
};

/// Irradiance, W/m^2 per RGB channel: `direct` arrives straight from lights and emissive
/// surfaces, `indirect` after one or more reflections (total = direct + indirect).
struct IrradianceEstimate {
  std::vector<glm::vec3> direct;
  std::vector<glm::vec3> indirect;
  /// Per point and channel: the sampling variance of `indirect` (sample variance / samples),
  /// the estimate's own noise. 0 with a single sample.
  std::vector<glm::vec3> indirect_variance;
};

/// Estimates the irradiance at each point (samples_per_pixel samples each).
engine::Result<IrradianceEstimate> reference_irradiance(const BakeInput& input, std::span<const SurfacePoint> points,
                                                        const ReferenceSettings& settings);
engine::Result<IrradianceEstimate> reference_irradiance(const engine::Scene& scene,
                                                        std::span<const SurfacePoint> points,
                                                        const ReferenceSettings& settings);

/// Where a light-atlas texel's sample point (the surface point whose irradiance the texel
/// holds) lies.
enum class TexelPlacement : std::uint8_t {
  /// On the surface a camera sees: 0.05 texel inside its triangle (never on the line where a
  /// neighbouring surface begins) and moved in front of any back face within one texel (a
  /// floor running under a wall). The light atlas's final gather bakes here.
  VisibleSurface,
  /// Where the rasterizer puts it: the texel centre on its triangle, or the triangle's point
  /// closest to it, which may lie on a chart's border line or under other geometry. The VPL
  /// final shooting and the PRM bake here (their estimates lack the near field that texels
  /// moved next to concave edges need).
  Raster,
};

/// The ground truth of a light atlas: irradiance (W/m^2) at every texel of the layout a bake
/// of `input` gets at `texels_per_metre` (the static instances charted as the bakers chart
/// them), width x height, texel (x, y) at y * width + x; texels no triangle covers hold
/// their neighbours' values (dilated, as a baked atlas) and valid = 0.
struct AtlasReference {
  int width = 0;
  int height = 0;
  float texels_per_metre = 0.0f;  ///< The layout's (lower than asked when the atlas would exceed its size limit).
  std::vector<glm::vec3> direct;
  std::vector<glm::vec3> indirect;
  std::vector<glm::vec3> total;
  std::vector<std::uint8_t> valid;
  std::vector<glm::vec3> indirect_variance;  ///< Sampling variance of `indirect` (0 off the valid texels).
};
/// samples_per_pixel of `settings` is per texel. Errors: no static triangle, a layout that
/// cannot be built, bad settings, cancellation.
engine::Result<AtlasReference> reference_atlas(const BakeInput& input, float texels_per_metre,
                                               const ReferenceSettings& settings,
                                               TexelPlacement placement = TexelPlacement::VisibleSurface);

}  // namespace gi
