#pragma once
// Draco compression of one triangle primitive for KHR_draco_mesh_compression (private to
// the glTF writer).
//   auto d = engine::gltf::encode_draco_primitive(prim, {.position_bits = 14});
//   if (d) append(d->bytes);  // then emit the extension with d->position_id...

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <engine/scene_asset.h>

namespace engine::gltf {

/// Quantization bits per attribute (Draco's SetAttributeQuantization).
struct DracoQuantization {
  int position_bits = 14;
  int normal_bits = 10;
  int texcoord_bits = 12;
};

/// The compressed primitive and what the plain glTF accessors must say about it.
/// Counts and bounds are those of the decoded mesh (Draco may reorder or split vertices),
/// so the accessors match what a decoder produces.
struct DracoPrimitive {
  std::vector<std::uint8_t> bytes;  ///< The Draco bitstream for the bufferView.
  int position_id = -1;             ///< Draco attribute unique ids (-1: attribute absent).
  int normal_id = -1;
  int uv0_id = -1;
  int uv1_id = -1;
  std::size_t vertex_count = 0;  ///< Decoded point count (accessor count).
  std::size_t index_count = 0;   ///< Decoded faces x 3.
  glm::vec3 position_min{0.0f};  ///< Bounds of the decoded positions.
  glm::vec3 position_max{0.0f};
};

/// Encodes `primitive` (edgebreaker, quantized). Returns false with `error` set when Draco
/// rejects it. Non-indexed primitives are encoded as sequential triangles.
bool encode_draco_primitive(const Primitive& primitive, const DracoQuantization& bits, DracoPrimitive& out,
                            std::string& error);

}  // namespace engine::gltf
