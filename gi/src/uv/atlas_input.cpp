#include "uv/atlas_input.h"

#include <engine/check.h>

#include <cmath>
#include <string>

namespace gi {
namespace {

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Area-weighted vertex normals of one primitive (for primitives stored without normals).
std::vector<glm::vec3> face_normals(const BakePrimitive& p) {
  std::vector<glm::vec3> n(p.positions.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    const std::uint32_t a = p.indices[t], b = p.indices[t + 1], c = p.indices[t + 2];
    if (a >= n.size() || b >= n.size() || c >= n.size()) continue;
    const glm::vec3 w = glm::cross(p.positions[b] - p.positions[a], p.positions[c] - p.positions[a]);
    n[a] += w;
    n[b] += w;
    n[c] += w;
  }
  for (glm::vec3& v : n) {
    const float len = glm::length(v);
    v = len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return n;
}

std::string input_name(std::size_t i, const AtlasInputMesh& m) {
  return "input " + std::to_string(i) + " (id " + std::to_string(m.id) + ")";
}

}  // namespace

std::vector<AtlasInputMesh> atlas_inputs_from(const BakeInput& input) {
  std::vector<AtlasInputMesh> inputs;
  for (const BakeInstance& inst : input.instances) {
    if (inst.mobility != BakeMobility::Static || inst.mesh >= input.meshes.size()) continue;
    const glm::mat4& world = inst.object_to_world;
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(world)));
    AtlasInputMesh in;
    in.id = inst.id;
    for (const BakePrimitive& prim : input.meshes[inst.mesh].primitives) {
      const auto base = static_cast<std::uint32_t>(in.positions.size());
      for (const glm::vec3& p : prim.positions) in.positions.push_back(glm::vec3(world * glm::vec4(p, 1.0f)));
      const std::vector<glm::vec3> computed =
          prim.normals.size() == prim.positions.size() ? std::vector<glm::vec3>{} : face_normals(prim);
      const std::vector<glm::vec3>& local_normals = computed.empty() ? prim.normals : computed;
      for (const glm::vec3& n : local_normals) {
        const glm::vec3 w = normal_matrix * n;
        const float len = glm::length(w);
        in.normals.push_back(len > 0.0f ? w / len : w);
      }
      for (std::uint32_t i : prim.indices) in.indices.push_back(base + i);
    }
    inputs.push_back(std::move(in));
  }
  return inputs;
}

engine::Status validate_atlas_inputs(std::span<const AtlasInputMesh> inputs) {
  std::size_t triangles = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const AtlasInputMesh& m = inputs[i];
    const std::string where = input_name(i, m);
    if (m.indices.size() % 3 != 0)
      return engine::Error{"", where, "index count " + std::to_string(m.indices.size()) + " is not a multiple of 3"};
    if (!m.normals.empty() && m.normals.size() != m.positions.size())
      return engine::Error{"", where,
                           "has " + std::to_string(m.normals.size()) + " normals for " +
                               std::to_string(m.positions.size()) + " positions"};
    for (std::size_t k = 0; k < m.indices.size(); ++k)
      if (m.indices[k] >= m.positions.size())
        return engine::Error{"", where,
                             "index " + std::to_string(k) + " is " + std::to_string(m.indices[k]) +
                                 ", out of range (vertex count " + std::to_string(m.positions.size()) + ")"};
    for (std::size_t v = 0; v < m.positions.size(); ++v)
      if (!finite(m.positions[v]))
        return engine::Error{"", where, "position " + std::to_string(v) + " is not finite (NaN or Inf)"};
      else if (glm::any(glm::greaterThan(glm::abs(m.positions[v]), glm::vec3(kMaxAtlasCoordinateM))))
        return engine::Error{"", where,
                             "position " + std::to_string(v) + " is farther than " +
                                 std::to_string(static_cast<long long>(kMaxAtlasCoordinateM)) +
                                 " m from the origin (absurd scale)"};
    for (std::size_t v = 0; v < m.normals.size(); ++v)
      if (!finite(m.normals[v]))
        return engine::Error{"", where, "normal " + std::to_string(v) + " is not finite (NaN or Inf)"};
    triangles += m.indices.size() / 3;
  }
  if (triangles == 0) return engine::Error{"", "", "no static triangles to parameterize (empty scene)"};
  return {};
}

}  // namespace gi
