// Draco encoding of one primitive: builds a draco::Mesh with one attribute value per
// vertex, encodes it with quantization and decodes it back once, so the writer knows the
// exact vertex count and position bounds a reader will see.
#include "gltf/draco_encode.h"

#include <algorithm>
#include <limits>
#include <memory>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wnull-dereference"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wcast-align"
#pragma GCC diagnostic ignored "-Woverloaded-virtual"
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#pragma GCC diagnostic pop

namespace engine::gltf {
namespace {

// Adds a float attribute with one value per point; returns its unique id.
template <class Vec>
int add_float_attribute(draco::Mesh& mesh, draco::GeometryAttribute::Type type, const std::vector<Vec>& values) {
  constexpr int kComponents = Vec::length();
  draco::GeometryAttribute ga;
  ga.Init(type, nullptr, kComponents, draco::DT_FLOAT32, false, sizeof(float) * kComponents, 0);
  const int id = mesh.AddAttribute(ga, true, static_cast<draco::AttributeValueIndex::ValueType>(values.size()));
  draco::PointAttribute* att = mesh.attribute(id);
  for (std::size_t i = 0; i < values.size(); ++i) {
    float v[kComponents];
    for (int c = 0; c < kComponents; ++c) v[c] = values[i][c];
    att->SetAttributeValue(draco::AttributeValueIndex(static_cast<std::uint32_t>(i)), v);
  }
  return static_cast<int>(att->unique_id());
}

}  // namespace

// Long because it is one round trip: fill a draco::Mesh, encode it, decode the bytes again and
// read the counts and bounds the accessors need from the decoded mesh, each step on the last one's result.
bool encode_draco_primitive(const Primitive& primitive, const DracoQuantization& bits, DracoPrimitive& out,
                            std::string& error) {
  const std::size_t n = primitive.positions.size();
  draco::Mesh mesh;
  mesh.set_num_points(static_cast<draco::PointIndex::ValueType>(n));
  std::vector<std::uint32_t> indices = primitive.indices;
  if (indices.empty()) {
    indices.resize(n - n % 3);
    for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<std::uint32_t>(i);
  }
  mesh.SetNumFaces(indices.size() / 3);
  for (std::size_t f = 0; f < indices.size() / 3; ++f) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(indices[3 * f + k]);
    mesh.SetFace(draco::FaceIndex(static_cast<std::uint32_t>(f)), face);
  }
  out = DracoPrimitive{};
  out.position_id = add_float_attribute(mesh, draco::GeometryAttribute::POSITION, primitive.positions);
  if (!primitive.normals.empty())
    out.normal_id = add_float_attribute(mesh, draco::GeometryAttribute::NORMAL, primitive.normals);
  if (!primitive.uv0.empty())
    out.uv0_id = add_float_attribute(mesh, draco::GeometryAttribute::TEX_COORD, primitive.uv0);
  if (!primitive.uv1.empty())
    out.uv1_id = add_float_attribute(mesh, draco::GeometryAttribute::TEX_COORD, primitive.uv1);

  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits.position_bits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, bits.normal_bits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, bits.texcoord_bits);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  encoder.SetSpeedOptions(5, 5);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!status.ok()) {
    error = std::string("Draco encoding failed: ") + status.error_msg();
    return false;
  }
  out.bytes.assign(reinterpret_cast<const std::uint8_t*>(buffer.data()),
                   reinterpret_cast<const std::uint8_t*>(buffer.data()) + buffer.size());

  // Decode once: the accessors must describe the decoded mesh.
  draco::DecoderBuffer in;
  in.Init(buffer.data(), buffer.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) {
    error = std::string("Draco round trip failed: ") + decoded.status().error_msg();
    return false;
  }
  const draco::Mesh& dm = *decoded.value();
  out.vertex_count = dm.num_points();
  out.index_count = static_cast<std::size_t>(dm.num_faces()) * 3;
  const draco::PointAttribute* pos = dm.GetAttributeByUniqueId(static_cast<std::uint32_t>(out.position_id));
  if (pos == nullptr) {
    error = "Draco round trip lost the POSITION attribute";
    return false;
  }
  glm::vec3 lo(std::numeric_limits<float>::max());
  glm::vec3 hi(-std::numeric_limits<float>::max());
  for (draco::PointIndex p(0); p < dm.num_points(); ++p) {
    float v[3] = {0.0f, 0.0f, 0.0f};
    pos->ConvertValue<float, 3>(pos->mapped_index(p), v);
    const glm::vec3 q(v[0], v[1], v[2]);
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  out.position_min = lo;
  out.position_max = hi;
  return true;
}

}  // namespace engine::gltf
