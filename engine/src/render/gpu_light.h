#pragma once
// C++ mirror of GpuLight in engine/shaders/lighting_common.glsl (std430 SSBO, binding 0).

#include <glm/glm.hpp>

namespace engine::render {

enum class GpuLightType : int { Point = 0, Spot = 1, Directional = 2, Area = 3 };

struct GpuLight {
  glm::vec4 position_type{0.0f};             ///< xyz world position (m), w type
  glm::vec4 direction_range{0.0f};           ///< xyz unit emission direction, w range (m; 0 unlimited)
  glm::vec4 radiant{0.0f};                   ///< rgb colour x intensity (engine units), w directional: tan(disc radius)
  glm::vec4 cone{0.0f, 0.0f, -1.0f, -1.0f};  ///< cos outer, cos inner, 2-D shadow layer, shadow cube
  glm::vec4 area_half_x{0.0f};               ///< half extent along the light's X (m)
  glm::vec4 area_half_y{0.0f};               ///< half extent along the light's Y (m)
  glm::mat4 shadow_view_proj{1.0f};          ///< world -> clip of the 2-D shadow map
  glm::vec4 shadow_eye{0.0f, 0.0f, 0.0f, 1.0f};  ///< shadow eye (m), w far (m)
  glm::vec4 shadow_params{0.0f};  ///< x 0 ortho / 1 distance, y texel footprint, z area: index among area lights, w
                                  ///< area: texel footprint of its grazing-band cube map
  glm::vec4 flags{0.0f};  ///< x 1: the light does not move (Light::moves false), so a bake may hold its direct light
};
static_assert(sizeof(GpuLight) == 208, "GpuLight must match the std430 layout of lighting_common.glsl");

}  // namespace engine::render
