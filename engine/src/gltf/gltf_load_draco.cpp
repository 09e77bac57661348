// KHR_draco_mesh_compression decoding for the glTF loader. The loader decodes Draco
// itself rather than through tinygltf so that every index (buffer view, attribute id,
// face index) is checked and a corrupt or truncated bitstream is a clean error.

#include "gltf/gltf_load_internal.h"

#include <cmath>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#pragma GCC diagnostic pop

namespace engine::gltf_load {

// Long because it is one sequence over one decoded mesh: bound the bufferView, decode, check the
// limits, copy the faces, then each attribute, every step a check returning its own error.
Result<DracoPrimitive> decode_draco(const Context& ctx, const ParsedFile& file, const DracoRef& ref,
                                    const std::string& location) {
  const tinygltf::Model& model = file.model;
  const std::string where = location + " KHR_draco_mesh_compression";
  if (ref.buffer_view < 0 || static_cast<std::size_t>(ref.buffer_view) >= model.bufferViews.size()) {
    return ctx.error(where, "bufferView is out of range");
  }
  const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(ref.buffer_view)];
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size()) {
    return ctx.error(where, "bufferView refers to a missing buffer");
  }
  const std::size_t buffer_index = static_cast<std::size_t>(view.buffer);
  if (buffer_index < file.buffer_problems.size() && !file.buffer_problems[buffer_index].empty()) {
    return ctx.error(where,
                     "buffer " + std::to_string(view.buffer) + " has no data: " + file.buffer_problems[buffer_index]);
  }
  const std::vector<unsigned char>& buffer = model.buffers[buffer_index].data;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset) {
    return ctx.error(where, "bufferView is out of range of its buffer");
  }

  draco::DecoderBuffer input;
  input.Init(reinterpret_cast<const char*>(buffer.data() + view.byteOffset), view.byteLength);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&input);
  if (!decoded.ok()) {
    return ctx.error(where, "corrupt or truncated Draco data: " + decoded.status().error_msg_string());
  }
  const std::unique_ptr<draco::Mesh>& mesh = decoded.value();
  if (mesh == nullptr) return ctx.error(where, "corrupt Draco data: no mesh");

  DracoPrimitive out;
  out.vertex_count = mesh->num_points();
  if (out.vertex_count > ctx.options.limits.max_vertices_per_primitive) {
    return ctx.error(where, std::to_string(out.vertex_count) + " vertices exceed the limit");
  }
  const std::size_t faces = mesh->num_faces();
  if (faces * 3 > ctx.options.limits.max_indices_per_primitive) {
    return ctx.error(where, std::to_string(faces * 3) + " indices exceed the limit");
  }
  out.indices.reserve(faces * 3);
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
    const draco::Mesh::Face& face = mesh->face(f);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = face[k].value();
      if (v >= out.vertex_count) return ctx.error(where, "face index " + std::to_string(v) + " is out of range");
      out.indices.push_back(v);
    }
  }

  for (const auto& [semantic, id] : ref.attributes) {
    const draco::PointAttribute* attribute = mesh->GetAttributeByUniqueId(static_cast<std::uint32_t>(id));
    if (attribute == nullptr) {
      return ctx.error(where, "attribute '" + semantic + "' refers to missing Draco attribute " + std::to_string(id));
    }
    const int ncomp = attribute->num_components();
    if (ncomp < 1 || ncomp > 4) {
      return ctx.error(where, "attribute '" + semantic + "' has " + std::to_string(ncomp) + " components");
    }
    std::vector<float> values(out.vertex_count * static_cast<std::size_t>(ncomp));
    float tmp[4] = {0, 0, 0, 0};
    for (draco::PointIndex i(0); i < mesh->num_points(); ++i) {
      const draco::AttributeValueIndex value_index = attribute->mapped_index(i);
      if (value_index.value() >= attribute->size() ||
          !attribute->ConvertValue<float>(value_index, static_cast<std::int8_t>(ncomp), tmp)) {
        return ctx.error(where, "attribute '" + semantic + "' cannot be decoded");
      }
      for (int c = 0; c < ncomp; ++c) {
        // Checked like an accessor's elements (gltf_load_accessors.cpp): raw Draco floats
        // carry any bit pattern, and a NaN here would reach the renderer and the bakers.
        if (!std::isfinite(tmp[c])) {
          return ctx.error(where, "attribute '" + semantic + "' element " + std::to_string(i.value()) +
                                      " is not finite (NaN or Inf)");
        }
        values[i.value() * static_cast<std::size_t>(ncomp) + static_cast<std::size_t>(c)] = tmp[c];
      }
    }
    out.components[semantic] = ncomp;
    out.attributes[semantic] = std::move(values);
  }
  return out;
}

}  // namespace engine::gltf_load
