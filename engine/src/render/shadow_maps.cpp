#include "render/shadow_maps.h"

#include <algorithm>
#include <array>
#include <cmath>
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
    static_2d_ = GlTexture{};  // the static depth cache follows the maps' size (ensure_static_cache)
    static_content_2d_.clear();
  }
  if (cube_maps_.empty() || cube_size != cube_size_ || cubes > cubes_) {
    cube_maps_ = GlTexture::create_cube_array(GL_DEPTH_COMPONENT32F, cube_size, cubes);
    set_compare_sampling(cube_maps_.id());
    cube_size_ = cube_size;
    cubes_ = cubes;
    content_cube_.clear();
    static_cube_ = GlTexture{};
    static_content_cube_.clear();
  }
  if (framebuffer_.empty()) {
    framebuffer_ = GlFramebuffer::create();
    glNamedFramebufferDrawBuffer(framebuffer_.id(), GL_NONE);
    glNamedFramebufferReadBuffer(framebuffer_.id(), GL_NONE);
  }
}

namespace {

/// The 6 planes (a, b, c, d: inside where a x + b y + c z + d >= 0) of a view-projection's clip volume.
std::array<glm::vec4, 6> clip_planes(const glm::mat4& m) {
  const glm::vec4 r0(m[0][0], m[1][0], m[2][0], m[3][0]), r1(m[0][1], m[1][1], m[2][1], m[3][1]),
      r2(m[0][2], m[1][2], m[2][2], m[3][2]), r3(m[0][3], m[1][3], m[2][3], m[3][3]);
  return {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
}

/// False when a perspective shadow view's volume, widened by a quarter of its half-width on
/// each side (filter taps and a cube map's seamless filtering reach past a face's edge),
/// lies wholly outside one of the camera's clip planes: no pixel the camera sees can look
/// it up. Its corners: the eye (the near plane's corners, as close as it) and the far plane's.
bool may_be_seen(const glm::mat4& view_proj, const std::array<glm::vec4, 6>& camera_planes) {
  const glm::mat4 to_world = glm::inverse(view_proj);
  glm::vec3 corners[8];
  int n = 0;
  for (const float z : {-1.0f, 1.0f})
    for (const float x : {-1.25f, 1.25f})
      for (const float y : {-1.25f, 1.25f}) {
        const glm::vec4 w = to_world * glm::vec4(x, y, z, 1.0f);
        if (!(std::abs(w.w) > 0.0f)) return true;
        corners[n++] = glm::vec3(w) / w.w;
      }
  for (const glm::vec4& p : camera_planes) {
    bool all_outside = true;
    for (const glm::vec3& c : corners) all_outside = all_outside && glm::dot(glm::vec3(p), c) + p.w < 0.0f;
    if (all_outside) return false;
  }
  return true;
}

bool same_view(const ShadowView& a, const ShadowView& b) {
  return a.view_proj == b.view_proj && a.eye == b.eye && a.axis == b.axis && a.far_m == b.far_m &&
         a.ortho == b.ortho && a.cube == b.cube && a.layer == b.layer;
}

}  // namespace

bool ShadowMaps::LayerContent::operator==(const LayerContent& o) const {
  return same_view(view, o.view) && casters == o.casters;
}

int ShadowMaps::render(const std::vector<ShadowView>& views, const std::vector<DrawItem>& items,
                       const GpuScene& scene, const ShaderProgram& program, const glm::mat4& camera_view_proj) {
  // Each view's content first: the casters whose world bounds are not wholly outside one
  // of its clip planes (they would be clipped whole, so culling them changes no texel),
  // split into static (StaticTag) and dynamic ones for the static depth cache below.
  std::vector<LayerContent> wanted(views.size());
  std::vector<LayerContent> wanted_static(views.size());
  std::vector<std::vector<std::pair<const GpuMesh*, glm::mat4>>> dynamic(views.size());
  for (std::size_t k = 0; k < views.size(); ++k) {
    const ShadowView& v = views[k];
    wanted[k].view = v;
    wanted_static[k].view = v;
    const std::array<glm::vec4, 6> planes = clip_planes(v.view_proj);
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
      if (outside) continue;
      wanted[k].casters.emplace_back(item.mesh, item.model);
      (item.is_static ? wanted_static[k].casters : dynamic[k]).emplace_back(item.mesh, item.model);
    }
  }
  std::vector<std::size_t> stale;
  const std::array<glm::vec4, 6> camera_planes = clip_planes(camera_view_proj);
  unseen_views_ = 0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    std::vector<LayerContent>& held = views[k].cube ? content_cube_ : content_2d_;
    const auto slot = static_cast<std::size_t>(views[k].layer);
    if (slot < held.size() && held[slot] == wanted[k]) continue;
    // Only pixels the camera sees look a map up, so a stale view whose volume lies wholly
    // outside the camera's is left as it is: its record still says what its texels hold, so
    // it is drawn on the first frame the camera can see into it.
    if (!views[k].ortho && !may_be_seen(views[k].view_proj, camera_planes)) {
      ++unseen_views_;
      continue;
    }
    stale.push_back(k);
  }
  cached_views_ = 0;
  if (stale.empty()) return 0;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);  // both faces cast: open meshes and single planes stay opaque
  glDisable(GL_BLEND);
  program.use();
  glBindVertexArray(scene.vertex_array());
  const auto draw = [](const std::vector<std::pair<const GpuMesh*, glm::mat4>>& casters) {
    for (const auto& [mesh, model] : casters) {
      glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(model));
      for (const GpuPrimitive& p : mesh->primitives)
        glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                                 p.base_vertex);
    }
  };
  const float one = 1.0f;
  for (std::size_t k : stale) {
    const ShadowView& v = views[k];
    const int size = v.cube ? cube_size_ : map_size_;
    std::vector<LayerContent>& held = v.cube ? content_cube_ : content_2d_;
    const auto slot = static_cast<std::size_t>(v.layer);
    glViewport(0, 0, size, size);
    glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(v.view_proj));
    glUniform3fv(16, 1, glm::value_ptr(v.eye));
    glUniform1f(17, v.far_m);
    glUniform1i(18, v.ortho ? 1 : 0);
    glUniform3fv(19, 1, glm::value_ptr(v.axis));
    const std::uint32_t target = v.cube ? cube_maps_.id() : maps_2d_.id();
    // A light that did not move, whose dynamic casters did: its static casters' depth is kept
    // in a second texture, copied back, and only the dynamic casters are drawn over it. The
    // depth test keeps the nearest of both, so the layer holds exactly what drawing every
    // caster gives. A moving light (its view changed) draws everything: a cache would be
    // stale every frame.
    const bool light_still = slot < held.size() && same_view(held[slot].view, v);
    if (light_still && !dynamic[k].empty() && !wanted_static[k].casters.empty()) {
      ensure_static_cache();
      std::vector<LayerContent>& cached = v.cube ? static_content_cube_ : static_content_2d_;
      const std::uint32_t cache = v.cube ? static_cube_.id() : static_2d_.id();
      if (!(slot < cached.size() && cached[slot] == wanted_static[k])) {
        glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, cache, 0, v.layer);
        glClearNamedFramebufferfv(framebuffer_.id(), GL_DEPTH, 0, &one);
        draw(wanted_static[k].casters);
        if (cached.size() <= slot) cached.resize(slot + 1);
        cached[slot] = std::move(wanted_static[k]);
      } else {
        ++cached_views_;
      }
      const GLenum kind = v.cube ? GL_TEXTURE_CUBE_MAP_ARRAY : GL_TEXTURE_2D_ARRAY;
      glCopyImageSubData(cache, kind, 0, 0, 0, v.layer, target, kind, 0, 0, 0, v.layer, size, size, 1);
      glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, target, 0, v.layer);
      draw(dynamic[k]);
    } else {
      glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, target, 0, v.layer);
      glClearNamedFramebufferfv(framebuffer_.id(), GL_DEPTH, 0, &one);
      draw(wanted[k].casters);
    }
    if (held.size() <= slot) held.resize(slot + 1);
    held[slot] = std::move(wanted[k]);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return static_cast<int>(stale.size());
}

void ShadowMaps::ensure_static_cache() {
  if (static_2d_.empty()) {
    static_2d_ = GlTexture::create_2d_array(GL_DEPTH_COMPONENT32F, map_size_, map_size_, layers_2d_);
    static_content_2d_.clear();
  }
  if (static_cube_.empty()) {
    static_cube_ = GlTexture::create_cube_array(GL_DEPTH_COMPONENT32F, cube_size_, cubes_);
    static_content_cube_.clear();
  }
}

}  // namespace engine::render
