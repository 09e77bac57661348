#pragma once
// Per-frame data the renderer extracts from the registry: what to draw and where the
// shadow cameras are.

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/entity.h>

#include "render/gpu_scene.h"

namespace engine::render {

/// One MeshRenderer entity to draw.
/// World-space axis-aligned bounds (of one draw item, or of all).
struct SceneBounds {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  bool empty = true;
};

struct DrawItem {
  Entity entity;
  const GpuMesh* mesh = nullptr;
  glm::mat4 model{1.0f};
  std::int32_t material_override = -1;
  bool cast_shadows = true;
  bool is_static = false;  ///< StaticTag: indirect light from the atlas (TEXCOORD_1).
  SceneBounds bounds;      ///< item_bounds(*mesh, model), computed once per frame.
};

/// The box of the mesh's bounds' 8 corners placed by `model`.
SceneBounds item_bounds(const GpuMesh& mesh, const glm::mat4& model);

/// One shadow-map render: a camera and the layer it writes.
struct ShadowView {
  glm::mat4 view_proj{1.0f};
  glm::vec3 eye{0.0f};
  glm::vec3 axis{0.0f, 0.0f, -1.0f};  ///< Light direction (orthographic maps).
  float far_m = 1.0f;
  bool ortho = false;
  bool cube = false;  ///< Layer of the point-light cube-map array (cube * 6 + face) vs 2-D array.
  /// Layer of the directional lights' own 2-D array (ShadowCapacity::sun_size) vs the spot
  /// and area lights' array.
  bool sun = false;
  int layer = 0;
};

SceneBounds scene_bounds(const std::vector<DrawItem>& items);

}  // namespace engine::render
