#pragma once
// Reading GPU results back in the GL tests of gi (a context must be current).
//   std::vector<glm::vec3> atlas = gltest::read_texture(provider.frame().irradiance_atlas_texture, w, h);

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/indirect_light.h>

namespace gltest {

/// RGB of level 0 of a w x h RGBA float texture, row-major.
inline std::vector<glm::vec3> read_texture(std::uint32_t texture, int w, int h) {
  std::vector<float> rgba(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.size() * sizeof(float)), rgba.data());
  std::vector<glm::vec3> out(rgba.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]};
  return out;
}

/// The same for a provider's texture.
inline std::vector<glm::vec3> read_texture(engine::TextureHandle texture, int w, int h) {
  return read_texture(texture.gl_name, w, h);
}

}  // namespace gltest
