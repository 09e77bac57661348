#include "light_atlas/local_linear.h"

#include <cmath>

namespace gi {

glm::mat3 tangent_frame(const glm::vec3& n) {
  const glm::vec3 a = std::fabs(n.x) > 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 t = glm::normalize(glm::cross(a, n));
  return glm::mat3(t, glm::cross(n, t), n);
}

void to_linear_weights(float ridge, std::vector<Neighbour>& taken) {
  glm::dmat3 m(0.0);
  for (const Neighbour& t : taken) {
    const glm::dvec3 x(1.0, static_cast<double>(t.uv.x), static_cast<double>(t.uv.y));
    m += static_cast<double>(t.w) * glm::outerProduct(x, x);
  }
  const double ridge_w = (static_cast<double>(ridge) + 1e-9) * m[0][0];
  m[1][1] += ridge_w;
  m[2][2] += ridge_w;
  const glm::dvec3 r = glm::inverse(m) * glm::dvec3(1.0, 0.0, 0.0);
  for (Neighbour& t : taken)
    t.w = static_cast<float>(static_cast<double>(t.w) *
                             (r.x + r.y * static_cast<double>(t.uv.x) + r.z * static_cast<double>(t.uv.y)));
}

}  // namespace gi
