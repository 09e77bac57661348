#pragma once
// The reference path tracer's drivers over plain data: a pinhole image and irradiance at
// points, in parallel with per-item random streams (bit-identical for any thread count),
// progress reported and cancellation honoured between batches. gi/include/gi/reference.h
// wraps them for live engine scenes.
//   gi::PinholeCamera cam{.camera_to_world = m, .yfov_rad = 0.69f, .width = 256, .height = 256};
//   auto img = gi::render_reference(scene, cam, {.samples_per_pixel = 16});

#include <span>

#include <glm/glm.hpp>

#include <engine/image.h>
#include <engine/result.h>
#include <gi/reference.h>

#include "core/work_shard.h"
#include "raytrace/reference_scene.h"

namespace gi {

/// A camera looking along its local -Z with +Y up; aspect = width / height unless given.
struct PinholeCamera {
  glm::mat4 camera_to_world{1.0f};
  float yfov_rad = 0.8f;
  float aspect = 0.0f;
  int width = 256;
  int height = 256;
};

/// `shard` (docs/distributed-bake.md): only the pixels of the shard's blocks of 64 (in row-
/// major order) are traced, each exactly as in the whole image; the others keep RGB 0.
engine::Result<engine::ImageRgbaF> render_reference(const ReferenceScene& scene, const PinholeCamera& camera,
                                                    const ReferenceSettings& settings, const WorkShard& shard = {});

/// What the camera rays through the pixel centres (render_reference with jitter_pixels
/// false traces the same rays) hit first.
engine::Result<FirstHitImage> first_hits(const ReferenceScene& scene, const PinholeCamera& camera,
                                         unsigned threads = 0);

/// `shard`: only the points of the shard's blocks of 64 are estimated (the others stay 0).
engine::Result<IrradianceEstimate> estimate_irradiance(const ReferenceScene& scene,
                                                       std::span<const SurfacePoint> points,
                                                       const ReferenceSettings& settings, const WorkShard& shard = {});

}  // namespace gi
