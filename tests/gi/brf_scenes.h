#pragma once
// Meshes built in code for the basis-radiance-field tests.
//   gi::BrfMesh b = brftest::box({0.3f, 0.3f, 0.3f}, 6);   // 6 x 6 quads per face

#include <cstdint>

#include <glm/glm.hpp>

#include "brf/pca_basis.h"

namespace brftest {

/// A box of half extents `half` made of n x n quads per face, normals outwards, each face's
/// own vertices (hard edges). `inset` < 1 pulls the vertices inside their face (0.98: none
/// sits exactly on an edge, where two faces' normals meet).
inline gi::BrfMesh box(glm::vec3 half, int n, float inset = 0.98f) {
  gi::BrfMesh m;
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a)
    for (float sign : {-1.0f, 1.0f}) {
      const glm::vec3 nrm = axes[a] * sign;
      const glm::vec3 t = axes[(a + 1) % 3] * sign, b = axes[(a + 2) % 3];
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          const float s = (2.0f * static_cast<float>(i) / static_cast<float>(n) - 1.0f) * inset;
          const float r = (2.0f * static_cast<float>(j) / static_cast<float>(n) - 1.0f) * inset;
          m.positions.push_back((nrm + s * t + r * b) * half);
          m.normals.push_back(nrm);
        }
      const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

}  // namespace brftest
