// Mesh primitives of the glTF loader (glTF 2.0 §3.7.2): POSITION, NORMAL, TANGENT,
// TEXCOORD_0 and TEXCOORD_1 as triangle lists. Strips and fans become lists, points and lines are skipped,
// missing normals are computed, missing indices generated; morph targets and skins are
// ignored (the base mesh loads).

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <engine/log.h>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {
namespace {

constexpr int kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE;
constexpr int kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
constexpr int kShort = TINYGLTF_COMPONENT_TYPE_SHORT;
constexpr int kUInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;

/// Accessor layouts allowed for a vertex attribute by §3.7.2.1 (and, when the file uses
/// it, KHR_mesh_quantization).
bool attribute_layout_allowed(const std::string& semantic, const tinygltf::Accessor& acc, bool quantized) {
  const int ct = acc.componentType;
  if (semantic == "POSITION") {
    if (acc.type != TINYGLTF_TYPE_VEC3) return false;
    return ct == kFloat || (quantized && (ct == kByte || ct == kUByte || ct == kShort || ct == kUShort));
  }
  if (semantic == "NORMAL") {
    if (acc.type != TINYGLTF_TYPE_VEC3) return false;
    return ct == kFloat || (quantized && (ct == kByte || ct == kShort) && acc.normalized);
  }
  if (semantic == "TANGENT") {
    if (acc.type != TINYGLTF_TYPE_VEC4) return false;
    return ct == kFloat || (quantized && (ct == kByte || ct == kShort) && acc.normalized);
  }
  // TEXCOORD_n
  if (acc.type != TINYGLTF_TYPE_VEC2) return false;
  if (ct == kFloat) return true;
  if ((ct == kUByte || ct == kUShort) && acc.normalized) return true;
  return quantized && (ct == kByte || ct == kUByte || ct == kShort || ct == kUShort);
}

struct Attribute {
  std::vector<float> values;
  int components = 0;
};

/// One attribute of a primitive, from the Draco data when it is compressed there, else
/// from its accessor. Absent -> empty values.
Result<Attribute> read_attribute(const Context& ctx, const ParsedFile& file, const tinygltf::Primitive& prim,
                                 const DracoPrimitive* draco, const std::string& semantic, int expected_components,
                                 const std::string& where) {
  Attribute out;
  if (draco != nullptr) {
    const auto it = draco->attributes.find(semantic);
    if (it != draco->attributes.end()) {
      const int n = draco->components.at(semantic);
      if (n != expected_components) {
        return ctx.error(where, semantic + " has " + std::to_string(n) + " components in the Draco data, expected " +
                                    std::to_string(expected_components));
      }
      out.values = it->second;
      out.components = n;
      return out;
    }
  }
  const auto it = prim.attributes.find(semantic);
  if (it == prim.attributes.end()) return out;
  const int index = it->second;
  if (index < 0 || static_cast<std::size_t>(index) >= file.model.accessors.size()) {
    return ctx.error(where, semantic + " refers to accessor " + std::to_string(index) + ", which is out of range");
  }
  if (!file.accessor_problems.at(static_cast<std::size_t>(index)).empty()) {
    return ctx.error("accessor " + std::to_string(index), file.accessor_problems[static_cast<std::size_t>(index)]);
  }
  const tinygltf::Accessor& acc = file.model.accessors[static_cast<std::size_t>(index)];
  if (!attribute_layout_allowed(semantic, acc, file.mesh_quantization)) {
    return ctx.error("accessor " + std::to_string(index),
                     "componentType " + std::to_string(acc.componentType) + " / type " + std::to_string(acc.type) +
                         (acc.normalized ? " (normalized)" : "") + " is not allowed for " + semantic);
  }
  auto values = read_accessor(ctx, file, index, ctx.options.limits.max_vertices_per_primitive);
  if (!values) return values.error();
  out.values.assign(values->begin(), values->end());
  out.components = expected_components;
  return out;
}

template <class Vec>
std::vector<Vec> to_vectors(const std::vector<float>& flat) {
  constexpr int n = Vec::length();
  std::vector<Vec> out(flat.size() / n);
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (int c = 0; c < n; ++c) out[i][c] = flat[i * n + static_cast<std::size_t>(c)];
  }
  return out;
}

/// §3.7.2.1: strip triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}); fan triangle i is
/// (v_{i+1}, v_{i+2}, v_0).
std::vector<std::uint32_t> to_triangle_list(const std::vector<std::uint32_t>& idx, int mode) {
  std::vector<std::uint32_t> out;
  if (idx.size() < 3) return out;
  out.reserve((idx.size() - 2) * 3);
  for (std::size_t i = 0; i + 2 < idx.size(); ++i) {
    if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      out.insert(out.end(), {idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
    } else {
      out.insert(out.end(), {idx[i + 1], idx[i + 2], idx[0]});
    }
  }
  return out;
}

// NORMAL, TEXCOORD_0, TEXCOORD_1 and TANGENT of a primitive whose positions `out` holds, each
// absent or one per position; normals made unit, degenerate tangent sets dropped.
Status read_vertex_attributes(const Context& ctx, const ParsedFile& file, const tinygltf::Primitive& prim,
                              const DracoPrimitive* dp, const std::string& where, Primitive& out) {
  const std::size_t vertex_count = out.positions.size();
  auto normal = read_attribute(ctx, file, prim, dp, "NORMAL", 3, where);
  if (!normal) return normal.error();
  auto uv0 = read_attribute(ctx, file, prim, dp, "TEXCOORD_0", 2, where);
  if (!uv0) return uv0.error();
  auto uv1 = read_attribute(ctx, file, prim, dp, "TEXCOORD_1", 2, where);
  if (!uv1) return uv1.error();
  auto tangent = read_attribute(ctx, file, prim, dp, "TANGENT", 4, where);
  if (!tangent) return tangent.error();
  const std::pair<const char*, const Attribute*> others[] = {{"NORMAL", &normal.value()},
                                                             {"TEXCOORD_0", &uv0.value()},
                                                             {"TEXCOORD_1", &uv1.value()},
                                                             {"TANGENT", &tangent.value()}};
  for (const auto& [name, attr] : others) {
    const std::size_t count =
        attr->components == 0 ? 0 : attr->values.size() / static_cast<std::size_t>(attr->components);
    if (!attr->values.empty() && count != vertex_count) {
      return ctx.error(where, std::string(name) + " has " + std::to_string(count) + " elements, POSITION has " +
                                  std::to_string(vertex_count));
    }
  }
  out.normals = to_vectors<glm::vec3>(normal->values);
  for (glm::vec3& n : out.normals) {  // §3.7.2.1 wants unit normals; exporters round
    const float len = glm::length(n);
    n = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  out.uv0 = to_vectors<glm::vec2>(uv0->values);
  out.uv1 = to_vectors<glm::vec2>(uv1->values);
  // TANGENT (§3.7.2.1): xyz unit, w the handedness +-1. Exporters write zero tangents where
  // the UVs are degenerate; then the set is dropped with a warning and the renderer
  // generates it (engine/tangents.h), as it does for a file without tangents.
  out.tangents = to_vectors<glm::vec4>(tangent->values);
  for (std::size_t i = 0; i < out.tangents.size(); ++i) {
    glm::vec4& t = out.tangents[i];
    const float len = glm::length(glm::vec3(t));
    if (!std::isfinite(len) || len < 1e-6f || !std::isfinite(t.w) || t.w == 0.0f) {
      log_message(LogLevel::Warning, ctx.file + ": " + where + ": TANGENT " + std::to_string(i) +
                                         " is degenerate, tangents are generated instead");
      out.tangents.clear();
      break;
    }
    t = glm::vec4(glm::vec3(t) / len, t.w > 0.0f ? 1.0f : -1.0f);
  }
  return {};
}

// The primitive's indices as stored (Draco's, the indices accessor's, else 0..n-1), each
// checked against the vertex count.
Result<std::vector<std::uint32_t>> read_indices(const Context& ctx, const ParsedFile& file, int mesh_index,
                                                int prim_index, const DracoPrimitive* dp, std::size_t vertex_count,
                                                const std::string& where) {
  std::vector<std::uint32_t> indices;
  const auto stored_indices = file.primitive_indices.find({mesh_index, prim_index});
  const int indices_accessor = stored_indices != file.primitive_indices.end() ? stored_indices->second : -1;
  if (dp != nullptr) {  // Draco meshes carry their own triangle indices
    indices = dp->indices;
  } else if (indices_accessor >= 0) {
    if (static_cast<std::size_t>(indices_accessor) >= file.model.accessors.size()) {
      return ctx.error(where, "indices accessor " + std::to_string(indices_accessor) + " is out of range");
    }
    if (!file.accessor_problems.at(static_cast<std::size_t>(indices_accessor)).empty()) {
      return ctx.error("accessor " + std::to_string(indices_accessor),
                       file.accessor_problems[static_cast<std::size_t>(indices_accessor)]);
    }
    const tinygltf::Accessor& acc = file.model.accessors[static_cast<std::size_t>(indices_accessor)];
    // §3.7.2.1: indices are SCALAR unsigned byte/short/int, not normalized.
    if (acc.type != TINYGLTF_TYPE_SCALAR || acc.normalized ||
        (acc.componentType != kUByte && acc.componentType != kUShort && acc.componentType != kUInt)) {
      return ctx.error("accessor " + std::to_string(indices_accessor),
                       "is not a valid index accessor (SCALAR unsigned integer)");
    }
    auto values = read_accessor(ctx, file, indices_accessor, ctx.options.limits.max_indices_per_primitive);
    if (!values) return values.error();
    indices.reserve(values->size());
    for (double v : *values) indices.push_back(static_cast<std::uint32_t>(v));
  } else {
    indices.resize(vertex_count);
    for (std::size_t i = 0; i < vertex_count; ++i) indices[i] = static_cast<std::uint32_t>(i);
  }
  for (std::size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= vertex_count) {
      const std::string acc = indices_accessor >= 0 ? "accessor " + std::to_string(indices_accessor) : where;
      return ctx.error(acc, "index value " + std::to_string(indices[i]) + " at " + std::to_string(i) +
                                " is >= the vertex count " + std::to_string(vertex_count));
    }
  }
  return indices;
}

// `indices` of a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive as a triangle list.
std::vector<std::uint32_t> triangle_list(const Context& ctx, const std::string& where,
                                         std::vector<std::uint32_t> indices, int mode) {
  if (mode != TINYGLTF_MODE_TRIANGLES) return to_triangle_list(indices, mode);
  if (indices.size() % 3 != 0) {
    // Not an error for the validator (MESH_PRIMITIVE_INCOMPATIBLE_MODE): the trailing
    // partial triangle cannot be drawn and is dropped.
    log_message(LogLevel::Warning, ctx.file + ": " + where + ": " + std::to_string(indices.size()) +
                                       " indices do not make whole triangles, the last " +
                                       std::to_string(indices.size() % 3) + " dropped");
    indices.resize(indices.size() - indices.size() % 3);
  }
  return indices;
}

Result<std::optional<Primitive>> convert_primitive(const Context& ctx, const ParsedFile& file, int mesh_index,
                                                   int prim_index, const tinygltf::Primitive& prim) {
  const std::string where = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(prim_index);
  // §3.7.2.1 modes: 0 points, 1 lines, 2 line loop, 3 line strip, 4 triangles, 5 strip, 6 fan.
  if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) return std::optional<Primitive>{};
  if (prim.mode < TINYGLTF_MODE_TRIANGLES || prim.mode > TINYGLTF_MODE_TRIANGLE_FAN) {
    return ctx.error(where, "invalid mode " + std::to_string(prim.mode));
  }
  if (prim.material >= 0 && static_cast<std::size_t>(prim.material) >= file.model.materials.size()) {
    return ctx.error(where, "material " + std::to_string(prim.material) + " is out of range (" +
                                std::to_string(file.model.materials.size()) + " materials)");
  }
  std::optional<DracoPrimitive> draco;
  if (const auto it = file.draco.find({mesh_index, prim_index}); it != file.draco.end()) {
    auto decoded = decode_draco(ctx, file, it->second, where);
    if (!decoded) return decoded.error();
    draco = std::move(decoded.value());
  }
  const DracoPrimitive* dp = draco ? &*draco : nullptr;

  auto position = read_attribute(ctx, file, prim, dp, "POSITION", 3, where);
  if (!position) return position.error();
  if (position->values.empty()) {
    // §3.7.2.1 lets POSITION be absent (an extension may provide the geometry): nothing
    // the engine can draw, so the primitive is skipped like points and lines.
    log_message(LogLevel::Warning, ctx.file + ": " + where + ": no POSITION attribute, primitive skipped");
    return std::optional<Primitive>{};
  }
  Primitive out;
  out.material = prim.material;
  out.positions = to_vectors<glm::vec3>(position->values);
  if (Status s = read_vertex_attributes(ctx, file, prim, dp, where, out); !s) return s.error();
  auto indices = read_indices(ctx, file, mesh_index, prim_index, dp, out.positions.size(), where);
  if (!indices) return indices.error();
  out.indices = triangle_list(ctx, where, std::move(indices).value(), prim.mode);
  if (out.indices.empty()) {
    // Fewer than 3 indices (or a strip or fan of fewer than 3 vertices): no triangle to draw,
    // skipped like points and lines. Kept, it would read as a non-indexed primitive
    // (engine::Primitive: empty indices) whose vertices make no whole triangles.
    log_message(LogLevel::Warning, ctx.file + ": " + where + ": no whole triangle, primitive skipped");
    return std::optional<Primitive>{};
  }
  if (out.normals.empty()) out.normals = compute_smooth_normals(out.positions, out.indices);
  return std::optional<Primitive>{std::move(out)};
}

}  // namespace

std::vector<glm::vec3> compute_smooth_normals(const std::vector<glm::vec3>& positions,
                                              const std::vector<std::uint32_t>& indices) {
  // Each triangle adds its unnormalized face normal (length = twice its area) to its
  // vertices, so larger triangles weigh more.
  std::vector<glm::vec3> sum(positions.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const glm::vec3& a = positions[indices[t]];
    const glm::vec3& b = positions[indices[t + 1]];
    const glm::vec3& c = positions[indices[t + 2]];
    const glm::vec3 n = glm::cross(b - a, c - a);
    for (std::size_t k = 0; k < 3; ++k) sum[indices[t + k]] += n;
  }
  for (glm::vec3& n : sum) {
    const float len = glm::length(n);
    n = (len > 0.0f && std::isfinite(len)) ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return sum;
}

Result<std::vector<Mesh>> convert_meshes(const Context& ctx, const ParsedFile& file) {
  std::vector<Mesh> meshes;
  meshes.reserve(file.model.meshes.size());
  // Meshes no node uses keep their index but may be broken: they load empty with a warning.
  std::vector<bool> used(file.model.meshes.size(), false);
  if (const Json* nodes = find_member(file.doc, "nodes")) {
    for (const Json& n : *nodes) {
      const Json* mesh = find_member(n, "mesh");
      if (mesh != nullptr && mesh->is_number_unsigned() && mesh->get<std::size_t>() < used.size()) {
        used[mesh->get<std::size_t>()] = true;
      }
    }
  }
  for (std::size_t m = 0; m < file.model.meshes.size(); ++m) {
    const tinygltf::Mesh& src = file.model.meshes[m];
    Mesh mesh;
    mesh.name = src.name;
    if (src.primitives.empty()) return ctx.error("mesh " + std::to_string(m), "has no primitives");
    for (std::size_t p = 0; p < src.primitives.size(); ++p) {
      auto prim = convert_primitive(ctx, file, static_cast<int>(m), static_cast<int>(p), src.primitives[p]);
      if (!prim && used[m]) return prim.error();
      if (!prim) {
        log_message(LogLevel::Warning, prim.error().to_string() + " (mesh unused by any node, left empty)");
        mesh.primitives.clear();
        break;
      }
      if (prim->has_value()) mesh.primitives.push_back(std::move(**prim));
    }
    meshes.push_back(std::move(mesh));
  }
  return meshes;
}

}  // namespace engine::gltf_load
