#pragma once
// Turns the registry's enabled lights into GpuLight records and plans their shadow maps:
// directional (orthographic, fitted to the scene bounds seen along the light, in an array of
// their own at ShadowCapacity::sun_size), spot (perspective, the cone),
// area (perspective with a 150 degree field of view from the rectangle's centre; the shader
// soft-shadows it over the rectangle, shadow_common.glsl's shadow_area; beyond it, a cube
// map from the centre for the grazing band),
// point (a cube-map-array slice, six 90 degree faces).

#include <array>
#include <utility>
#include <vector>

#include <engine/registry.h>

#include "render/frame_data.h"
#include "render/gpu_light.h"

namespace engine::render {

struct ShadowCapacity {
  int map_size = 1024;     ///< Texels per side of a 2-D shadow map.
  int cube_size = 512;     ///< Texels per side of a cube face.
  int max_2d_layers = 8;   ///< Spot and area lights with shadows beyond this are unshadowed.
  int sun_size = 4096;     ///< Texels per side of a directional light's map (the whole level).
  int max_sun_layers = 2;  ///< Directional lights with shadows beyond this are unshadowed.
  int max_cubes = 4;       ///< Point lights with shadows beyond this are unshadowed.
  /// Area lights with a cube map for the grazing band beyond their 2-D map (more: unshadowed
  /// there). In the same cube-map array, after or between the point lights' cubes.
  int max_area_cubes = 4;
};

struct LightList {
  /// Sorted by GpuLightType: points, then spots, directionals, areas.
  std::vector<GpuLight> lights;
  /// The entity of each of `lights` (same order).
  std::vector<Entity> entities;
  /// Number of lights of each GpuLightType.
  std::array<int, 4> count_by_type{};
  std::vector<ShadowView> shadow_views;
  int layers_2d = 0;
  int sun_layers = 0;
  int cubes = 0;
};

/// Lights whose values or world transform are unusable (engine/runtime_limits.h) are left
/// out and, when `skipped` is set, listed there with why.
LightList collect_lights(const Registry& registry, const SceneBounds& bounds, const ShadowCapacity& capacity,
                         std::vector<std::pair<Entity, const char*>>* skipped = nullptr);

}  // namespace engine::render
