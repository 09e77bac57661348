// engine::generate_tangents (engine/tangents.h): MikkTSpace's convention, written here.
#include <engine/tangents.h>

#include <cmath>

namespace engine {

namespace {

/// A unit vector orthogonal to n (Duff et al. 2017), for vertices without usable UVs.
glm::vec3 any_orthogonal(const glm::vec3& n) {
  const float sgn = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (sgn + n.z);
  return glm::vec3(1.0f + sgn * n.x * n.x * a, sgn * n.x * n.y * a, -sgn * n.x);
}

}  // namespace

std::vector<glm::vec4> generate_tangents(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                                         const std::vector<glm::vec2>& uvs, const std::vector<std::uint32_t>& indices) {
  const std::size_t n = positions.size();
  std::vector<glm::vec3> tan(n, glm::vec3(0.0f));
  std::vector<glm::vec3> bitan(n, glm::vec3(0.0f));
  const std::size_t corners = indices.empty() ? n : indices.size();
  const auto at = [&](std::size_t c) { return indices.empty() ? c : static_cast<std::size_t>(indices[c]); };
  for (std::size_t t = 0; t + 2 < corners; t += 3) {
    const std::size_t i0 = at(t), i1 = at(t + 1), i2 = at(t + 2);
    if (i0 >= n || i1 >= n || i2 >= n) continue;
    const glm::vec3 e1 = positions[i1] - positions[i0];
    const glm::vec3 e2 = positions[i2] - positions[i0];
    const glm::vec2 d1 = uvs[i1] - uvs[i0];
    const glm::vec2 d2 = uvs[i2] - uvs[i0];
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (!(std::abs(det) > 1e-20f)) continue;  // degenerate UVs: no direction
    // dP/du and dP/dv of the triangle's linear map times |det| (its UV area x 2): each
    // triangle weighs by its UV area, only the direction of the sum is kept.
    const float r = det > 0.0f ? 1.0f : -1.0f;
    const glm::vec3 dpdu = (e1 * d2.y - e2 * d1.y) * r;
    const glm::vec3 dpdv = (e2 * d1.x - e1 * d2.x) * r;
    for (std::size_t k : {i0, i1, i2}) {
      tan[k] += dpdu;
      bitan[k] += dpdv;
    }
  }
  std::vector<glm::vec4> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 nrm = glm::length(normals[i]) > 0.0f ? glm::normalize(normals[i]) : glm::vec3(0.0f, 0.0f, 1.0f);
    glm::vec3 t = tan[i] - nrm * glm::dot(nrm, tan[i]);  // Gram-Schmidt against the normal
    const float len = glm::length(t);
    if (!(len > 1e-12f) || !std::isfinite(len)) {
      out[i] = glm::vec4(any_orthogonal(nrm), 1.0f);
      continue;
    }
    t /= len;
    const float w = glm::dot(glm::cross(nrm, t), bitan[i]) < 0.0f ? -1.0f : 1.0f;
    out[i] = glm::vec4(t, w);
  }
  return out;
}

}  // namespace engine
