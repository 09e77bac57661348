#pragma once
// Ground truth of the light atlas: the reference path tracer's irradiance at every valid
// texel of a rasterized atlas (direct, indirect and total), dilated across chart borders
// like a baked atlas so it can be sampled bilinearly. Bakers are compared against it on the
// valid texels only.
//   auto texels = gi::rasterize_atlas(layout, inputs);
//   auto truth = gi::reference_atlas_irradiance(scene, texels, {.samples_per_pixel = 256});

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/reference.h>

#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

#include "uv/atlas_rasterizer.h"

namespace gi {

/// Per-texel irradiance (W/m^2, RGB), width x height, texel (x, y) at y * width + x.
struct AtlasIrradiance {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> direct;
  std::vector<glm::vec3> indirect;
  std::vector<glm::vec3> total;
  std::vector<std::uint8_t> valid;           ///< Texels a triangle covers (the others hold dilated values or 0).
  std::vector<glm::vec3> indirect_variance;  ///< Sampling variance of `indirect` (0 off the valid texels).
};

/// The sample points of `texels`: its valid texels in index order (a texel's point index is
/// its place among them, what its random stream and shard block are numbered by), each with
/// the geometric normal of its triangle among the static instances of `input` (the ones
/// `texels` were rasterized from) turned to its shading normal's side, as the gather takes it.
std::vector<SurfacePoint> atlas_sample_points(const BakeInput& input, const AtlasTexels& texels);

/// The atlas from the estimate at atlas_sample_points(texels): values put in place, dilated,
/// total = direct + indirect. What reference_atlas_irradiance and a merge of shards both run.
AtlasIrradiance assemble_atlas_irradiance(const AtlasTexels& texels, const IrradianceEstimate& estimate);

/// samples_per_pixel of `settings` is per texel.
engine::Result<AtlasIrradiance> reference_atlas_irradiance(const BakeInput& input, const AtlasTexels& texels,
                                                           const ReferenceSettings& settings);

}  // namespace gi
