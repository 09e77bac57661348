#include <engine/components.h>

#include <glm/gtc/matrix_transform.hpp>

namespace engine {

glm::mat4 Transform::local_matrix() const {
  glm::mat4 m = glm::translate(glm::mat4(1.0f), position);
  m *= glm::mat4_cast(rotation);
  return glm::scale(m, scale);
}

}  // namespace engine
