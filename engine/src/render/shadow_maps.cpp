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

void ShadowMaps::reserve_array(Kind kind, int size, int layers) {
  MapArray& a = maps_[kind];
  layers = std::max(layers, 1);
  if (!a.texture.empty() && size == a.size && layers <= a.layers) return;
  a.texture = kind == kCubeMaps ? GlTexture::create_cube_array(GL_DEPTH_COMPONENT32F, size, layers)
                                : GlTexture::create_2d_array(GL_DEPTH_COMPONENT32F, size, size, layers);
  set_compare_sampling(a.texture.id());
  a.size = size;
  a.layers = layers;
  a.content.clear();             // new, empty textures
  a.static_cache = GlTexture{};  // the static depth cache follows the maps' size (ensure_static_cache)
  a.static_content.clear();
}

void ShadowMaps::reserve(int map_size, int layers_2d, int sun_size, int sun_layers, int cube_size, int cubes) {
  reserve_array(kMaps2d, map_size, layers_2d);
  reserve_array(kSunMaps, sun_size, sun_layers);
  reserve_array(kCubeMaps, cube_size, cubes);
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
  return a.view_proj == b.view_proj && a.eye == b.eye && a.axis == b.axis && a.far_m == b.far_m && a.ortho == b.ortho &&
         a.cube == b.cube && a.sun == b.sun && a.layer == b.layer;
}

}  // namespace

bool ShadowMaps::LayerContent::operator==(const LayerContent& o) const {
  return same_view(view, o.view) && casters == o.casters;
}

ShadowMaps::ViewContents ShadowMaps::contents_of(const std::vector<ShadowView>& views,
                                                 const std::vector<DrawItem>& items) {
  ViewContents c;
  c.wanted.resize(views.size());
  c.wanted_static.resize(views.size());
  c.dynamic.resize(views.size());
  for (std::size_t k = 0; k < views.size(); ++k) {
    const ShadowView& v = views[k];
    c.wanted[k].view = v;
    c.wanted_static[k].view = v;
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
      const Caster caster{item.mesh, item.model, item.material_override};
      c.wanted[k].casters.push_back(caster);
      (item.is_static ? c.wanted_static[k].casters : c.dynamic[k]).push_back(caster);
    }
  }
  return c;
}

std::vector<std::size_t> ShadowMaps::stale_views(const std::vector<ShadowView>& views,
                                                 const std::vector<LayerContent>& wanted,
                                                 const glm::mat4& camera_view_proj) {
  std::vector<std::size_t> stale;
  const std::array<glm::vec4, 6> camera_planes = clip_planes(camera_view_proj);
  unseen_views_ = 0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const std::vector<LayerContent>& held = maps_[kind_of(views[k])].content;
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
  return stale;
}

void ShadowMaps::draw_casters(const std::vector<Caster>& casters, const ShadowView& view, const Programs& programs) {
  const auto set_view = [&](const DepthUniforms& u) {
    glUniformMatrix4fv(u.view_proj, 1, GL_FALSE, glm::value_ptr(view.view_proj));
    glUniform3fv(u.eye, 1, glm::value_ptr(view.eye));
    glUniform1f(u.far_m, view.far_m);
    glUniform1i(u.ortho, view.ortho ? 1 : 0);
    glUniform3fv(u.axis, 1, glm::value_ptr(view.axis));
  };
  for (const bool cut_out : {false, true}) {
    if (cut_out && programs.cut_out == nullptr) break;
    const LocatedProgram<DepthUniforms>& p = cut_out ? *programs.cut_out : *programs.opaque;
    bool used = false;
    for (const Caster& c : casters) {
      bool model_set = false;
      for (const GpuPrimitive& prim : c.mesh->primitives) {
        const GpuMaterial& m = programs.scene->material(c.material_override >= 0 ? c.material_override : prim.material);
        if (m.cut_out() != cut_out) continue;
        if (!used) {
          p.use();
          set_view(p.uniforms);
          used = true;
        }
        if (!model_set) {
          glUniformMatrix4fv(p.uniforms.model, 1, GL_FALSE, glm::value_ptr(c.model));
          model_set = true;
        }
        if (cut_out) bind_alpha_test(m, m.alpha_mode == AlphaMode::Mask ? m.alpha_cutoff : 0.5f, p.uniforms.material);
        glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(prim.index_count), GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(prim.first_index) * 4u),
                                 prim.base_vertex);
      }
    }
  }
}

void ShadowMaps::render_layer(const ShadowView& v, std::size_t k, ViewContents& contents, const Programs& programs) {
  const float one = 1.0f;
  const Kind kind = kind_of(v);
  MapArray& maps = maps_[kind];
  const int size = maps.size;
  std::vector<LayerContent>& held = maps.content;
  const auto slot = static_cast<std::size_t>(v.layer);
  glViewport(0, 0, size, size);
  const std::uint32_t target = maps.texture.id();
  // A light that did not move, whose dynamic casters did: its static casters' depth is kept
  // in a second texture, copied back, and only the dynamic casters are drawn over it. The
  // depth test keeps the nearest of both, so the layer holds exactly what drawing every
  // caster gives. A moving light (its view changed) draws everything: a cache would be
  // stale every frame.
  const bool light_still = slot < held.size() && same_view(held[slot].view, v);
  if (light_still && !contents.dynamic[k].empty() && !contents.wanted_static[k].casters.empty()) {
    ensure_static_cache(kind);
    std::vector<LayerContent>& cached = maps.static_content;
    const std::uint32_t cache = maps.static_cache.id();
    if (!(slot < cached.size() && cached[slot] == contents.wanted_static[k])) {
      glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, cache, 0, v.layer);
      glClearNamedFramebufferfv(framebuffer_.id(), GL_DEPTH, 0, &one);
      draw_casters(contents.wanted_static[k].casters, v, programs);
      if (cached.size() <= slot) cached.resize(slot + 1);
      cached[slot] = std::move(contents.wanted_static[k]);
    } else {
      ++cached_views_;
    }
    const GLenum gl_kind = v.cube ? GL_TEXTURE_CUBE_MAP_ARRAY : GL_TEXTURE_2D_ARRAY;
    glCopyImageSubData(cache, gl_kind, 0, 0, 0, v.layer, target, gl_kind, 0, 0, 0, v.layer, size, size, 1);
    glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, target, 0, v.layer);
    draw_casters(contents.dynamic[k], v, programs);
  } else {
    glNamedFramebufferTextureLayer(framebuffer_.id(), GL_DEPTH_ATTACHMENT, target, 0, v.layer);
    glClearNamedFramebufferfv(framebuffer_.id(), GL_DEPTH, 0, &one);
    draw_casters(contents.wanted[k].casters, v, programs);
  }
  if (held.size() <= slot) held.resize(slot + 1);
  held[slot] = std::move(contents.wanted[k]);
}

int ShadowMaps::render(const std::vector<ShadowView>& views, const std::vector<DrawItem>& items, const GpuScene& scene,
                       const LocatedProgram<DepthUniforms>& program,
                       const LocatedProgram<DepthUniforms>* cut_out_program, const glm::mat4& camera_view_proj) {
  // Each view's content first: the casters whose world bounds are not wholly outside one
  // of its clip planes (they would be clipped whole, so culling them changes no texel),
  // split into static (StaticTag) and dynamic ones for the static depth cache.
  ViewContents contents = contents_of(views, items);
  const std::vector<std::size_t> stale = stale_views(views, contents.wanted, camera_view_proj);
  cached_views_ = 0;
  if (stale.empty()) return 0;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);  // both faces cast: open meshes and single planes stay opaque
  glDisable(GL_BLEND);
  glBindVertexArray(scene.vertex_array());
  const Programs programs{&scene, &program, cut_out_program};
  for (std::size_t k : stale) render_layer(views[k], k, contents, programs);
  unbind_material_samplers();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return static_cast<int>(stale.size());
}

void ShadowMaps::ensure_static_cache(Kind kind) {
  MapArray& a = maps_[kind];
  if (!a.static_cache.empty()) return;
  a.static_cache = kind == kCubeMaps ? GlTexture::create_cube_array(GL_DEPTH_COMPONENT32F, a.size, a.layers)
                                     : GlTexture::create_2d_array(GL_DEPTH_COMPONENT32F, a.size, a.size, a.layers);
  a.static_content.clear();
}

}  // namespace engine::render
