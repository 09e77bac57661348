#pragma once
// Whether every component of a GLM value is finite (no NaN, no infinity): the check every
// reader and validator makes before it trusts positions, normals, transforms and colours.
//   if (!engine::all_finite(matrix)) return error("non-finite transform");

#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace engine {

template <glm::length_t L, class T, glm::qualifier Q>
bool all_finite(const glm::vec<L, T, Q>& v) {
  for (glm::length_t i = 0; i < L; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

template <glm::length_t C, glm::length_t R, class T, glm::qualifier Q>
bool all_finite(const glm::mat<C, R, T, Q>& m) {
  for (glm::length_t c = 0; c < C; ++c)
    if (!all_finite(m[c])) return false;
  return true;
}

template <class T, glm::qualifier Q>
bool all_finite(const glm::qua<T, Q>& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

}  // namespace engine
