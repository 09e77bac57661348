#include "render/shadow_maps.h"

#include <algorithm>

#include <GL/glcorearb.h>
#include <glm/gtc/type_ptr.hpp>

namespace engine::render {

namespace {

void set_compare_sampling(std::uint32_t texture) {
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(texture, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
}

}  // namespace

void ShadowMaps::reserve(int map_size, int layers_2d, int cube_size, int cubes) {
  layers_2d = std::max(layers_2d, 1);
  cubes = std::max(cubes, 1);
  if (maps_2d_.empty() || map_size != map_size_ || layers_2d > layers_2d_) {
    maps_2d_ = GlTexture::create_2d_array(GL_DEPTH_COMPONENT32F, map_size, map_size, layers_2d);
    set_compare_sampling(maps_2d_.id());
    map_size_ = map_size;
    layers_2d_ = layers_2d;
  }
  if (cube_maps_.empty() || cube_size != cube_size_ || cubes > cubes_) {
    cube_maps_ = GlTexture::create_cube_array(GL_DEPTH_COMPONENT32F, cube_size, cubes);
    set_compare_sampling(cube_maps_.id());
    cube_size_ = cube_size;
    cubes_ = cubes;
  }
  if (framebuffer_.empty()) {
    framebuffer_ = GlFramebuffer::create();
    glNamedFramebufferDrawBuffer(framebuffer_.id(), GL_NONE);
    glNamedFramebufferReadBuffer(framebuffer_.id(), GL_NONE);
  }
}

void ShadowMaps::render(const std::vector<ShadowView>& views, const std::vector<DrawItem>& items,
                        const GpuScene& scene, const ShaderProgram& program) {
  if (views.empty()) return;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);  // both faces cast: open meshes and single planes stay opaque
  glDisable(GL_BLEND);
  program.use();
  glBindVertexArray(scene.vertex_array());
  for (const ShadowView& v : views) {
    const int size = v.cube ? cube_size_ : map_size_;
    glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, v.cube ? cube_maps_.id() : maps_2d_.id(), 0,
                                   v.layer);
    glViewport(0, 0, size, size);
    const float one = 1.0f;
    glClearNamedFramebufferfv(framebuffer_.id(), GL_DEPTH, 0, &one);
    glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(v.view_proj));
    glUniform3fv(16, 1, glm::value_ptr(v.eye));
    glUniform1f(17, v.far_m);
    glUniform1i(18, v.ortho ? 1 : 0);
    glUniform3fv(19, 1, glm::value_ptr(v.axis));
    for (const DrawItem& item : items) {
      if (!item.cast_shadows) continue;
      glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(item.model));
      for (const GpuPrimitive& p : item.mesh->primitives)
        glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                                 p.base_vertex);
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace engine::render
