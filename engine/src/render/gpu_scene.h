#pragma once
// The scene's meshes, materials and textures on the GPU: one interleaved vertex buffer and
// one index buffer for every primitive of every mesh, plus per-material draw parameters.

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/gpu/gl_objects.h>
#include <engine/result.h>
#include <engine/scene_asset.h>

namespace engine::render {

/// Vertex layout of the scene vertex buffer (locations 0..3 of forward/shadow shaders).
struct GpuVertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv0;
  glm::vec2 uv1;
};
static_assert(sizeof(GpuVertex) == 40, "GpuVertex is tightly packed");

struct GpuPrimitive {
  std::uint32_t first_index = 0;  ///< Offset into the index buffer (indices).
  std::uint32_t index_count = 0;
  std::int32_t base_vertex = 0;   ///< Scene vertex of the primitive's vertex 0.
  int material = -1;
};

struct GpuMesh {
  std::int32_t first_vertex = 0;  ///< Scene vertex where the mesh's concatenated primitives start.
  std::uint32_t vertex_count = 0;
  glm::vec3 bounds_min{0.0f};
  glm::vec3 bounds_max{0.0f};
  std::vector<GpuPrimitive> primitives;
  /// Every triangle's corners in the mesh's space (3 per triangle, all primitives): the CPU
  /// copy the light reach grid tests shadow rays against (engine/light_reach.h).
  std::vector<glm::vec3> triangle_corners;
};

struct GpuMaterial {
  glm::vec4 base_color{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  glm::vec3 emissive{0.0f};
  float specular_factor = 1.0f;
  glm::vec3 specular_color_factor{1.0f};
  bool double_sided = false;
  std::uint32_t base_color_texture = 0;  ///< GL names (0: the white default).
  std::uint32_t metallic_roughness_texture = 0;
  std::uint32_t emissive_texture = 0;
};

class GpuScene {
 public:
  /// Uploads every primitive and material. Errors name the mesh/primitive that is malformed.
  static Result<GpuScene> upload(const SceneAsset& assets);

  const std::vector<GpuMesh>& meshes() const { return meshes_; }
  /// Material `index`, or the default (white, dielectric, roughness 1) for -1/out of range.
  const GpuMaterial& material(int index) const;
  std::uint32_t vertex_array() const { return vao_.id(); }
  std::uint32_t white_texture() const { return white_.id(); }

 private:
  GlBuffer vertices_;
  GlBuffer indices_;
  GlVertexArray vao_;
  GlTexture white_;
  std::vector<GlTexture> textures_;
  std::vector<GpuMesh> meshes_;
  std::vector<GpuMaterial> materials_;
  GpuMaterial default_material_;
};

}  // namespace engine::render
