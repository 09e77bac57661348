#pragma once
// The scene's meshes, materials and textures on the GPU: one interleaved vertex buffer and
// one index buffer for every primitive of every mesh, plus per-material draw parameters.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <engine/gpu/gl_objects.h>
#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene_asset.h>

namespace engine::render {

struct MaterialUniforms;  // render/program_uniforms.h

/// Vertex layout of the scene vertex buffer (locations 0..4 of forward/shadow shaders).
struct GpuVertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv0;
  glm::vec2 uv1;
  /// Location 4: the normal map's tangent (Primitive::tangents, or engine::generate_tangents
  /// from the normal texture's UV set); zero where the material has no normal texture.
  glm::vec4 tangent;
};
static_assert(sizeof(GpuVertex) == 56, "GpuVertex is tightly packed");

/// Texture units of a material's textures (forward.frag.glsl, material_common.glsl).
enum MaterialUnit : unsigned {
  kMaterialBaseColorUnit = 0,
  kMaterialMetallicRoughnessUnit = 1,
  kMaterialEmissiveUnit = 2,
  kMaterialNormalUnit = 15
};

/// Texture slots of a material, in the order of GpuMaterial::texcoord_sets / uv_transforms.
enum MaterialSlot : int { kBaseColorSlot = 0, kMetallicRoughnessSlot = 1, kNormalSlot = 2, kEmissiveSlot = 3 };

struct GpuPrimitive {
  std::uint32_t first_index = 0;  ///< Offset into the index buffer (indices).
  std::uint32_t index_count = 0;
  std::int32_t base_vertex = 0;  ///< Scene vertex of the primitive's vertex 0.
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
  std::uint32_t normal_texture = 0;  ///< 0: no normal map (the vertex normal shades).
  float normal_scale = 1.0f;
  /// GL sampler objects per slot (MaterialSlot), made per distinct TextureSampler; 0 for an
  /// absent texture (the white default's own parameters).
  std::array<std::uint32_t, 4> samplers{};
  glm::ivec4 texcoord_sets{0};  ///< Per slot: TEXCOORD_0 or TEXCOORD_1.
  /// Per slot two rows (xyz) of KHR_texture_transform as a 2x3 matrix: uv' = (row0 . (uv, 1),
  /// row1 . (uv, 1)). Identity rows by default, which give uv exactly.
  std::array<glm::vec4, 8> uv_transforms{glm::vec4(1, 0, 0, 0), glm::vec4(0, 1, 0, 0), glm::vec4(1, 0, 0, 0),
                                         glm::vec4(0, 1, 0, 0), glm::vec4(1, 0, 0, 0), glm::vec4(0, 1, 0, 0),
                                         glm::vec4(1, 0, 0, 0), glm::vec4(0, 1, 0, 0)};
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  /// Drawn with its alpha tested in the depth passes: MASK at its cutoff; BLEND casts
  /// shadows as a cut-out at 0.5 (docs/scene-format.md).
  bool cut_out() const { return alpha_mode != AlphaMode::Opaque; }
};

/// Sets `m`'s texturing uniforms (material_common.glsl: TEXCOORD sets, transforms, alpha mode
/// and cutoff) on the current program, whose locations `at` holds.
void set_material_texturing(const GpuMaterial& m, const MaterialUniforms& at);
/// For the alpha-tested depth passes (ALPHA_TEST in material_common.glsl): the texturing
/// uniforms, base alpha and `cutoff`, and the base colour texture and its sampler on unit 0.
void bind_alpha_test(const GpuMaterial& m, float cutoff, const MaterialUniforms& at);
/// Unbinds the sampler objects set_material_texturing's callers bound (units 0, 1, 2, 15), so
/// later passes sample their textures with the textures' own parameters.
void unbind_material_samplers();

class GpuScene {
 public:
  /// Uploads every primitive and material. Errors name the mesh/primitive that is malformed.
  static Result<GpuScene> upload(const SceneAsset& assets);
  /// Replaces the meshes drawn in place of the scene's on static entities (an indirect-light
  /// provider's atlas meshes, engine/indirect_light.h) by `atlas`: atlas[k] becomes
  /// meshes()[scene_mesh_count() + k]. Invalidates pointers into meshes(). On error (a
  /// malformed mesh, named) nothing changes.
  Status set_atlas_meshes(std::span<const AtlasMesh> atlas);
  /// The SceneAsset's meshes: meshes()[0, scene_mesh_count()).
  std::size_t scene_mesh_count() const { return scene_meshes_; }

  const std::vector<GpuMesh>& meshes() const { return meshes_; }
  /// Material `index`, or the default (white, dielectric, roughness 1) for -1/out of range.
  const GpuMaterial& material(int index) const;
  std::uint32_t vertex_array() const { return vao_.id(); }
  std::uint32_t white_texture() const { return white_.id(); }
  /// Some material is MASK (the depth passes need their alpha-tested variants).
  bool has_mask() const { return has_mask_; }
  /// Some material is MASK or BLEND (the shadow maps need the alpha-tested variant).
  bool has_cut_out() const { return has_cut_out_; }

 private:
  // Vertices and indices of meshes being uploaded, after `first_vertex` / `first_index` of
  // the buffers.
  struct MeshGeometry {
    std::size_t first_vertex = 0;
    std::size_t first_index = 0;
    std::vector<GpuVertex> vertices;
    std::vector<std::uint32_t> indices;
  };
  /// `mesh`'s primitives appended to `out`, checked (errors at `file`, `name`).
  Result<GpuMesh> append_mesh(const Mesh& mesh, const std::string& file, const std::string& name,
                              MeshGeometry& out) const;
  /// A vertex array over vertices_ and indices_ (GpuVertex's locations 0..4).
  void bind_vertex_array();
  /// Every material's textures, samplers and draw parameters.
  Status upload_materials(const SceneAsset& assets);

  GlBuffer vertices_;
  GlBuffer indices_;
  GlVertexArray vao_;
  GlTexture white_;
  std::vector<GlTexture> textures_;
  std::vector<GlSampler> samplers_;
  std::vector<GpuMesh> meshes_;
  std::vector<GpuMaterial> materials_;
  GpuMaterial default_material_;
  bool has_mask_ = false;
  bool has_cut_out_ = false;
  /// Per material: the TEXCOORD set of its normal texture (tangents are made from it), -1: none.
  std::vector<int> normal_texcoords_;
  std::size_t scene_meshes_ = 0;    ///< Meshes of the SceneAsset (the atlas meshes follow).
  std::size_t scene_vertices_ = 0;  ///< Their vertices and indices, at the buffers' start.
  std::size_t scene_indices_ = 0;
};

}  // namespace engine::render
