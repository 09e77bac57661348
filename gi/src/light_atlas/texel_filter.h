#pragma once
// Step 4 of the texel gather (texel_gather.h): the edge-aware filter in world space.
//   out = gi::filter_world(texels, work, values, hidden, radius_m, texel_m, pool);

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "core/thread_pool.h"
#include "transport/static_scene.h"

namespace gi {

/// `e` filtered over the texels of `work` that are not `hidden`: each takes the Gaussian
/// mean (radius `radius_m`) of the texels on its plane (normals within ~18 degrees, plane
/// distance below half of `texel_m`), across chart borders. Hidden texels keep their value.
/// With `slope_ridge` >= 0, the intercept of a local linear fit with those weights instead
/// of their mean (local_linear.h). Bit-identical for any thread count.
std::vector<glm::vec3> filter_world(const AtlasTexels& texels, std::span<const std::uint32_t> work,
                                    const std::vector<glm::vec3>& e, const std::vector<std::uint8_t>& hidden,
                                    float radius_m, float texel_m, ThreadPool& pool, float slope_ridge = -1.0f);

}  // namespace gi
