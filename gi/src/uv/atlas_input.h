#pragma once
// The plain-data input of light-atlas parameterization: one static mesh instance in world
// space per entry, from a BakeInput (gi/bake_input.h).
//   std::vector<gi::AtlasInputMesh> inputs = gi::atlas_inputs_from(input);
//   auto layout = gi::build_atlas_layout(inputs, {.texels_per_metre = 32.0f});

#include <engine/result.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// One static mesh instance, already transformed to world space (metres).
/// Triangles are `indices[3t..3t+2]`; `normals` is empty or has one unit normal per position.
struct AtlasInputMesh {
  std::vector<glm::vec3> positions;  ///< World space, metres.
  std::vector<glm::vec3> normals;    ///< World space shading normals (may be empty).
  std::vector<std::uint32_t> indices;
  std::int64_t id = -1;  ///< The caller's id; atlas_inputs_from() stores the instance's id (a node index).
};

/// One input per Static instance, in instance order. The mesh's primitives are concatenated
/// in order: vertex k = i + (vertex counts of the earlier primitives) is primitive p's
/// vertex i, and indices are offset the same way (the engine's convention). Positions and
/// normals are transformed to world space (normals by the inverse transpose and
/// renormalized); a primitive without normals gets area-weighted face normals. Nothing is
/// validated here (see validate_atlas_inputs); out-of-range indices are copied as they are.
std::vector<AtlasInputMesh> atlas_inputs_from(const BakeInput& input);

/// Coordinates beyond this many metres are rejected: float spacing there (6 cm at 1e6 m) is
/// too coarse for an atlas, and areas of such triangles overflow.
inline constexpr float kMaxAtlasCoordinateM = 1.0e6f;

/// Checks what the atlas builder and rasterizer rely on: at least one triangle overall, index
/// counts divisible by 3, indices in range, finite positions within kMaxAtlasCoordinateM, normals empty or one per
/// position and finite. The error's location names the input ("input 3 (id 7)").
engine::Status validate_atlas_inputs(std::span<const AtlasInputMesh> inputs);

}  // namespace gi
