#include "uv/atlas_input.h"

#include <engine/check.h>

#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <string>

namespace gi {
namespace {

glm::mat4 local_matrix(const engine::Node& n) {
  const glm::mat4 t =
      glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0, 1, 0, 0), glm::vec4(0, 0, 1, 0), glm::vec4(n.translation, 1.0f));
  const glm::mat4 s = glm::mat4(glm::vec4(n.scale.x, 0, 0, 0), glm::vec4(0, n.scale.y, 0, 0),
                                glm::vec4(0, 0, n.scale.z, 0), glm::vec4(0, 0, 0, 1));
  return t * glm::mat4_cast(n.rotation) * s;
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Area-weighted vertex normals of one primitive (for primitives stored without normals).
std::vector<glm::vec3> face_normals(const engine::Primitive& p) {
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

glm::mat4 node_world_matrix(const engine::SceneAsset& scene, int node) {
  GI_EXPECTS(node >= 0 && static_cast<std::size_t>(node) < scene.nodes.size(), "node indexes scene.nodes");
  glm::mat4 m(1.0f);
  // Bounded walk: a malformed parent chain cannot loop forever.
  std::size_t steps = 0;
  for (int i = node; i >= 0 && static_cast<std::size_t>(i) < scene.nodes.size() && steps <= scene.nodes.size();
       i = scene.nodes[static_cast<std::size_t>(i)].parent, ++steps)
    m = local_matrix(scene.nodes[static_cast<std::size_t>(i)]) * m;
  return m;
}

std::vector<AtlasInputMesh> atlas_inputs_from(const engine::SceneAsset& scene) {
  std::vector<AtlasInputMesh> inputs;
  for (std::size_t ni = 0; ni < scene.nodes.size(); ++ni) {
    const engine::Node& node = scene.nodes[ni];
    if (node.mesh < 0 || static_cast<std::size_t>(node.mesh) >= scene.meshes.size()) continue;
    if (node.gi.mobility == engine::Mobility::Dynamic) continue;
    const glm::mat4 world = node_world_matrix(scene, static_cast<int>(ni));
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(world)));
    AtlasInputMesh in;
    in.id = static_cast<std::int64_t>(ni);
    for (const engine::Primitive& prim : scene.meshes[static_cast<std::size_t>(node.mesh)].primitives) {
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
