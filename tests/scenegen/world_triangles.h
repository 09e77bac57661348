#pragma once
// Test helpers: world matrices of SceneAsset nodes, their triangles in world space, and a
// brute-force segment-vs-triangle visibility test.
//   auto tris = world_triangles(asset);
//   bool blocked = segment_blocked(p, q, tris, [](const WorldTriangle&) { return true; });

#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <engine/scene_asset.h>

namespace scenegen_test {

inline glm::mat4 local_matrix(const engine::Node& n) {
  glm::mat4 m(1.0f);
  m[3] = glm::vec4(n.translation, 1.0f);
  return m * glm::mat4_cast(n.rotation) *
         glm::mat4(glm::vec4(n.scale.x, 0, 0, 0), glm::vec4(0, n.scale.y, 0, 0), glm::vec4(0, 0, n.scale.z, 0),
                   glm::vec4(0, 0, 0, 1));
}

inline glm::mat4 world_matrix(const engine::SceneAsset& s, int node) {
  glm::mat4 m(1.0f);
  for (int i = node; i >= 0; i = s.nodes[static_cast<std::size_t>(i)].parent)
    m = local_matrix(s.nodes[static_cast<std::size_t>(i)]) * m;
  return m;
}

inline int find_node(const engine::SceneAsset& s, const std::string& name) {
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    if (s.nodes[i].name == name) return static_cast<int>(i);
  return -1;
}

struct WorldTriangle {
  glm::vec3 a, b, c;
  glm::vec3 normal;  ///< From the winding (front face).
  std::string node;
};

inline std::vector<WorldTriangle> world_triangles(const engine::SceneAsset& s) {
  std::vector<WorldTriangle> out;
  for (std::size_t i = 0; i < s.nodes.size(); ++i) {
    const engine::Node& n = s.nodes[i];
    if (n.mesh < 0) continue;
    const glm::mat4 m = world_matrix(s, static_cast<int>(i));
    for (const engine::Primitive& p : s.meshes[static_cast<std::size_t>(n.mesh)].primitives)
      for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
        WorldTriangle w;
        w.a = glm::vec3(m * glm::vec4(p.positions[p.indices[t]], 1.0f));
        w.b = glm::vec3(m * glm::vec4(p.positions[p.indices[t + 1]], 1.0f));
        w.c = glm::vec3(m * glm::vec4(p.positions[p.indices[t + 2]], 1.0f));
        w.normal = glm::normalize(glm::cross(w.b - w.a, w.c - w.a));
        w.node = n.name;
        out.push_back(w);
      }
  }
  return out;
}

/// Moller-Trumbore: does the open segment p->q (ends excluded by `eps` of its length) hit t?
inline bool segment_hits(glm::vec3 p, glm::vec3 q, const WorldTriangle& t, float eps = 1e-4f) {
  const glm::vec3 d = q - p;
  const glm::vec3 e1 = t.b - t.a, e2 = t.c - t.a;
  const glm::vec3 h = glm::cross(d, e2);
  const float det = glm::dot(e1, h);
  if (std::fabs(det) < 1e-12f) return false;
  const float inv = 1.0f / det;
  const glm::vec3 s = p - t.a;
  const float u = glm::dot(s, h) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const glm::vec3 qv = glm::cross(s, e1);
  const float v = glm::dot(d, qv) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float tt = glm::dot(e2, qv) * inv;
  return tt > eps && tt < 1.0f - eps;
}

/// Sample points over a triangle, about `spacing` metres apart, pushed 1 mm off the
/// front face.
inline std::vector<glm::vec3> sample_triangle(const WorldTriangle& t, float spacing) {
  const float longest = std::max({glm::length(t.b - t.a), glm::length(t.c - t.b), glm::length(t.a - t.c)});
  const int n = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
  std::vector<glm::vec3> pts;
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      const float u = (static_cast<float>(i) + 1.0f / 3.0f) / static_cast<float>(n);
      const float v = (static_cast<float>(j) + 1.0f / 3.0f) / static_cast<float>(n);
      pts.push_back(t.a + u * (t.b - t.a) + v * (t.c - t.a) + 1e-3f * t.normal);
    }
  return pts;
}

}  // namespace scenegen_test
