#pragma once
// Plain triangle data for the ray casters: geometries in object space and instances that
// place them in the world. Bakers fill it through the adapter (scene_adapter.h), never from
// the registry directly.

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include <engine/scene_asset.h>

namespace gi {

/// The cut-outs of a geometry: glTF alphaMode MASK (alpha below the cutoff is cut out) and
/// BLEND (baked as a cut-out at alpha 0.5, docs/materials-in-bakes.md). Every ray caster
/// ignores a hit where cut() says so, closest-hit and shadow rays alike.
///   geo.cutout = std::make_shared<gi::RtAlphaCutout>(std::move(cutout));
struct RtAlphaCutout {
  /// One cut-out material: alpha = factor x the base colour texture's alpha (width 0: none).
  struct Mask {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> alpha;  ///< width x height, rows top to bottom.
    int texcoord = 0;                 ///< The UV set it reads (0: uv0, 1: uv1).
    engine::TextureSampler sampler;
    engine::TextureTransform transform;
    float factor = 1.0f;  ///< The base colour alpha factor.
    float cutoff = 0.5f;  ///< Alpha below it is cut out.
  };
  std::vector<Mask> masks;
  std::vector<std::int32_t> triangle_mask;  ///< Per triangle: index into masks, -1: opaque.
  std::vector<glm::vec2> uv0, uv1;          ///< Per vertex (empty when no mask reads that set).

  /// Alpha at barycentrics (u, v) of `triangle` (bilinear at full resolution): 1 when opaque.
  float alpha(const std::vector<std::uint32_t>& indices, std::uint32_t triangle, glm::vec2 bary) const;
  /// True when the point (u, v) of `triangle` is cut out.
  bool cut(const std::vector<std::uint32_t>& indices, std::uint32_t triangle, glm::vec2 bary) const;
};

struct RtGeometry {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;  ///< 3 per triangle.
  /// Cut-outs (alpha MASK / BLEND materials), shared by copies; null: every triangle is opaque.
  std::shared_ptr<const RtAlphaCutout> cutout;
};

struct RtInstance {
  std::uint32_t geometry = 0;
  glm::mat4 object_to_world{1.0f};
  /// Dynamic instances may get a new transform every frame (set_instance_transform).
  bool dynamic = false;
  /// Caller's id for the instance (e.g. the engine entity id); not used by the casters.
  std::uint64_t user_id = 0;
};

struct RtSceneData {
  std::vector<RtGeometry> geometries;
  std::vector<RtInstance> instances;
};

}  // namespace gi
