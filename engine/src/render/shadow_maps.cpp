#include "render/shadow_maps.h"

#include <algorithm>
#include <utility>

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
    content_2d_.clear();  // new, empty textures
  }
  if (cube_maps_.empty() || cube_size != cube_size_ || cubes > cubes_) {
    cube_maps_ = GlTexture::create_cube_array(GL_DEPTH_COMPONENT32F, cube_size, cubes);
    set_compare_sampling(cube_maps_.id());
    cube_size_ = cube_size;
    cubes_ = cubes;
    content_cube_.clear();
  }
  if (framebuffer_.empty()) {
    framebuffer_ = GlFramebuffer::create();
    glNamedFramebufferDrawBuffer(framebuffer_.id(), GL_NONE);
    glNamedFramebufferReadBuffer(framebuffer_.id(), GL_NONE);
  }
}

bool ShadowMaps::LayerContent::operator==(const LayerContent& o) const {
  const ShadowView& a = view;
  const ShadowView& b = o.view;
  return a.view_proj == b.view_proj && a.eye == b.eye && a.axis == b.axis && a.far_m == b.far_m &&
         a.ortho == b.ortho && a.cube == b.cube && a.layer == b.layer && casters == o.casters;
}

int ShadowMaps::render(const std::vector<ShadowView>& views, const std::vector<DrawItem>& items,
                       const GpuScene& scene, const ShaderProgram& program) {
  // Each view's content first: the casters whose world bounds are not wholly outside one
  // of its clip planes (they would be clipped whole, so culling them changes no texel).
  std::vector<LayerContent> wanted(views.size());
  for (std::size_t k = 0; k < views.size(); ++k) {
    const ShadowView& v = views[k];
    wanted[k].view = v;
    const glm::mat4& m = v.view_proj;
    const glm::vec4 r0(m[0][0], m[1][0], m[2][0], m[3][0]), r1(m[0][1], m[1][1], m[2][1], m[3][1]),
        r2(m[0][2], m[1][2], m[2][2], m[3][2]), r3(m[0][3], m[1][3], m[2][3], m[3][3]);
    const glm::vec4 planes[6] = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
    for (const DrawItem& item : items) {
      if (!item.cast_shadows) continue;
      const glm::vec3& lo = item.bounds.min;
      const glm::vec3& hi = item.bounds.max;
      bool outside = false;
      for (const glm::vec4& p : planes) {
        // The box corner furthest along the plane's normal.
        const glm::vec3 far(p.x >= 0.0f ? hi.x : lo.x, p.y >= 0.0f ? hi.y : lo.y, p.z >= 0.0f ? hi.z : lo.z);
        if (glm::dot(glm::vec3(p), far) + p.w < 0.0f) {
          outside = true;
          break;
        }
      }
      if (!outside) wanted[k].casters.emplace_back(item.mesh, item.model);
    }
  }
  std::vector<std::size_t> stale;
  for (std::size_t k = 0; k < views.size(); ++k) {
    std::vector<LayerContent>& held = views[k].cube ? content_cube_ : content_2d_;
    const auto slot = static_cast<std::size_t>(views[k].layer);
    if (slot < held.size() && held[slot] == wanted[k]) continue;
    stale.push_back(k);
  }
  if (stale.empty()) return 0;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);  // both faces cast: open meshes and single planes stay opaque
  glDisable(GL_BLEND);
  program.use();
  glBindVertexArray(scene.vertex_array());
  for (std::size_t k : stale) {
    const ShadowView& v = views[k];
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
    for (const auto& [mesh, model] : wanted[k].casters) {
      glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(model));
      for (const GpuPrimitive& p : mesh->primitives)
        glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                                 p.base_vertex);
    }
    std::vector<LayerContent>& held = v.cube ? content_cube_ : content_2d_;
    const auto slot = static_cast<std::size_t>(v.layer);
    if (held.size() <= slot) held.resize(slot + 1);
    held[slot] = std::move(wanted[k]);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return static_cast<int>(stale.size());
}

}  // namespace engine::render
