#pragma once
// The rigid objects a scene needs basis radiance fields for: one BrfSource per distinct mesh
// of a Dynamic instance of a BakeInput (gi/bake_input.h). Instanced props (five crates, one
// mesh) share one source.
//   auto sources = gi::dynamic_brf_meshes(input).value();
//   for (const gi::BrfSource& s : sources) bake(s.mesh);   // s.instances: who draws it
//
// Vertex order: the mesh's primitives concatenated in order, each primitive's vertices in
// its own order — exactly the order of the renderer's per-vertex irradiance buffer
// (engine::IndirectLightFrame::vertex_irradiance_buffer), so a baked basis Psi_i(x_j) and
// that buffer index the same vertices.

#include <engine/result.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "brf/brdf_separation.h"
#include "brf/pca_basis.h"

namespace gi {

/// One distinct dynamic mesh and the instances that draw it.
struct BrfSource {
  /// Unique among the scene's sources, a plain file-name fragment ([A-Za-z0-9_-]): the
  /// glTF mesh name with other characters replaced by '_', "_2", "_3"... added on a clash.
  std::string name;
  std::uint32_t mesh_index = 0;         ///< Into BakeInput::meshes.
  std::int32_t material_override = -1;  ///< The instances' BakeInstance::material_override.
  BrfMesh mesh;                         ///< Object space; reflectance per vertex.
  /// The glossy lobe the bake separates (brf_glossy_lobe of its material); none: diffuse.
  std::optional<GlossyLobe> glossy;
  glm::vec3 specular{1.0f};              ///< Glossy colour: f0 (RGB) / glossy->f0.
  std::string mesh_hash;                 ///< brf_mesh_hash(mesh, glossy): what a bake depends on.
  std::vector<std::uint32_t> instances;  ///< Into BakeInput::instances, ascending.
};

/// A box of half extents `half` around the origin made of n x n quads per face, normals
/// outwards, each face's own vertices (hard edges). `inset` < 1 pulls the vertices inside
/// their face (0.98: none sits exactly on an edge, where two faces' normals meet). For
/// tests, benchmarks and tools that need a rigid object without a scene.
BrfMesh brf_box_mesh(glm::vec3 half, int n, float inset = 0.98f);

/// 16 lowercase hex digits (XXH3-64) over the vertex count, positions, normals, indices
/// and reflectance of `mesh`, in order, then the glossy lobe when there is one. A bake whose
/// stored hash differs is stale.
std::string brf_mesh_hash(const BrfMesh& mesh, const std::optional<GlossyLobe>& glossy = std::nullopt);

/// A material whose lobe BRF carries as glossy terms: roughness below 0.6 (GGX alpha < 0.36:
/// a lobe directional enough that reflecting it diffusely misplaces its light, and broad
/// enough for a few separable terms, brdf_separation.h) and a specular reflectance f0 of at
/// least 0.2 in some channel (metals; a dielectric's 0.04 sends too little light to
/// matter next to its diffuse part). Returns the lobe (f0: the channels' mean) or none.
std::optional<GlossyLobe> brf_glossy_lobe(const BakeMaterial& material, glm::vec3* specular = nullptr);

/// Mesh `mesh_index` of `input` as a BrfMesh: positions, unit normals (area-weighted from the
/// triangles where a primitive has none), indices rebased onto the concatenation, and per
/// vertex the luminance (Rec. 709) of its material's hemispherical albedo (the fold every
/// baker uses; textures are not read); `material_override` >= 0 replaces every primitive's material, as the renderer
/// does. Errors (naming the mesh): out-of-range mesh index or vertex index, non-finite
/// positions or normals, no triangle.
engine::Result<BrfMesh> brf_mesh_from_input(const BakeInput& input, std::uint32_t mesh_index,
                                            std::int32_t material_override = -1);

/// One source per distinct (mesh, material override) of the Dynamic instances, in order of
/// the first instance drawing it. No dynamic mesh: empty. Errors: as brf_mesh_from_input.
engine::Result<std::vector<BrfSource>> dynamic_brf_meshes(const BakeInput& input);

/// The RGB reflectance the runtime bounces with for `source`: its (first) material's
/// hemispherical albedo (engine::gltf_hemispherical_albedo, both lobes, as the light atlas
/// folds it); for a glossy source its diffuse lobe's only (the specular lobe is its glossy
/// terms). The glTF default material when it has none.
glm::vec3 brf_source_albedo(const BakeInput& input, const BrfSource& source);

}  // namespace gi
