#pragma once
// Meshes built in code for the basis-radiance-field tests.
//   gi::BrfMesh b = brftest::box({0.3f, 0.3f, 0.3f}, 6);   // 6 x 6 quads per face

#include <glm/glm.hpp>

#include "brf/brf_mesh.h"

namespace brftest {

/// gi::brf_box_mesh (brf_mesh.h), as the tests name it.
inline gi::BrfMesh box(glm::vec3 half, int n, float inset = 0.98f) { return gi::brf_box_mesh(half, n, inset); }

}  // namespace brftest
