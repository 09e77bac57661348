#pragma once
// Per-vertex tangent frames for tangent-space normal maps, for primitives whose file has no
// TANGENT attribute. Follows MikkTSpace's convention (the one glTF's TANGENT assumes): the
// tangent points along increasing u of the normal map's UV set, the bitangent along
// increasing v, w = +1 when cross(normal, tangent) is the bitangent, -1 when it is mirrored.
// Not bit-exact with MikkTSpace (which splits vertices at UV seams and weights by angle):
// per-triangle tangents from the UV derivatives, accumulated per vertex, Gram-Schmidt
// orthonormalised against the vertex normal.
//   std::vector<glm::vec4> t = engine::generate_tangents(prim.positions, normals, prim.uv0, prim.indices);
//   // t[i].xyz unit, orthogonal to normals[i]; t[i].w = +-1

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace engine {

/// Tangents (xyz unit, w handedness +-1), one per position. `normals` and `uvs` have one entry
/// per position; `indices` is a triangle list (empty: positions in order). Vertices whose
/// triangles all have degenerate UVs get any unit vector orthogonal to their normal, w = +1.
std::vector<glm::vec4> generate_tangents(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                                         const std::vector<glm::vec2>& uvs, const std::vector<std::uint32_t>& indices);

}  // namespace engine
