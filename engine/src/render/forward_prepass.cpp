// engine::render::ForwardRenderer's work before shading: the HDR target cleared to the sky,
// the depth pre-pass (with the light-reach stencil when there is a reach grid) and its
// alpha-tested variants, the half-resolution area shadows, then the state that shades only
// each pixel's visible surface.
#include "render/forward_renderer.h"

#include <string>
#include <utility>

#include <GL/glcorearb.h>
#include <glm/gtc/type_ptr.hpp>

#include <engine/check.h>
#include <engine/gpu/shader_program.h>
#include <engine/log.h>
#include <engine/sky.h>

#include "render/gpu_scene.h"

namespace engine::render {

// The HDR target cleared to the sky, the depth pre-pass (and the reach stencil), the
// half-resolution area shadows; then the state that shades only each pixel's visible surface.
void ForwardRenderer::begin_forward_pass(const CameraView& view, const std::vector<DrawItem>& items, bool reach) {
  glBindFramebuffer(GL_FRAMEBUFFER, hdr_fbo_.id());
  glViewport(0, 0, width_, height_);
  // Where no geometry is, the camera sees the sky (black without one), as the path tracer does.
  // With a gradient, the horizon's radiance (what a level camera sees at the image's centre).
  const glm::vec3 sky_bg = sky_radiance(settings_.sky_radiance, settings_.sky_gradient, glm::vec3(1.0f, 0.0f, 0.0f));
  const float background[4] = {sky_bg.x, sky_bg.y, sky_bg.z, 1.0f};
  const float far_depth = 1.0f;
  glClearNamedFramebufferfv(hdr_fbo_.id(), GL_COLOR, 0, background);
  glClearNamedFramebufferfi(hdr_fbo_.id(), GL_DEPTH_STENCIL, 0, far_depth, 0);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  glBindVertexArray(scene_.vertex_array());
  depth_prepass(view.view_proj, items, reach);
  if (!area_lights_.empty()) {
    area_shadow_passes(view.view_proj, view.position, items);
    glBindFramebuffer(GL_FRAMEBUFFER, hdr_fbo_.id());
    glViewport(0, 0, width_, height_);
    glBindVertexArray(scene_.vertex_array());
    glBindTextureUnit(kAreaVisibilityUnit, area_visibility_.id());
  }
  // Shade only the visible surface of each pixel (llvmpipe pays per shaded fragment).
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  if (reach) {  // ... with the lights of its reach mask (the stencil the pre-pass wrote)
    glEnable(GL_STENCIL_TEST);
    glStencilMask(0);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  }
}

// The depth-only fragment stage `fragment` with ALPHA_TEST 1 (shadow.vert.glsl's vertices).
const LocatedProgram<DepthUniforms>& ForwardRenderer::alpha_test_program(const char* fragment) {
  auto it = alpha_test_programs_.find(fragment);
  if (it != alpha_test_programs_.end()) return it->second;
  ShaderProgramBuilder b(engine_shader_files());
  b.define("ALPHA_TEST 1");
  Result<LocatedProgram<DepthUniforms>> p = link_program<DepthUniforms>(
      std::move(b), {{ShaderStage::Vertex, "shadow.vert.glsl"}, {ShaderStage::Fragment, fragment}});
  if (!p) log_message(LogLevel::Error, p.error().to_string());
  GI_EXPECTS(p.ok(), "alpha-tested depth shader must compile");
  return alpha_test_programs_.emplace(fragment, std::move(p.value())).first->second;
}

// The pre-pass's depth (and reach stencil) of every opaque and MASK primitive: opaque ones
// first, then the MASK ones with the alpha-tested variant of the same program (a discard costs
// llvmpipe its early depth test, so only they pay it). BLEND primitives write no depth.
void ForwardRenderer::depth_prepass(const glm::mat4& view_proj, const std::vector<DrawItem>& items, bool reach) {
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  if (reach) {  // the nearest surface's reach mask into the stencil
    glEnable(GL_STENCIL_TEST);
    glStencilMask(0xFF);
    glStencilFunc(GL_ALWAYS, 0, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glBindTextureUnit(kReachUnit, reach_.texture.id());
  }
  for (const bool cut_out : {false, true}) {
    if (cut_out && !scene_.has_mask()) break;
    const LocatedProgram<DepthUniforms>& program =
        cut_out ? alpha_test_program(reach ? "depth_reach.frag.glsl" : "depth_only.frag.glsl")
                : (reach ? depth_reach_ : depth_only_);
    const DepthUniforms& u = program.uniforms;
    program.use();
    glUniformMatrix4fv(u.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
    if (reach) {
      glUniform3fv(u.reach_origin, 1, glm::value_ptr(reach_.grid.origin));
      glUniform1f(u.reach_inv_voxel, 1.0f / reach_.grid.voxel_m);
      glUniform1i(u.reach_all, reach_.grid.all);
    }
    for (const DrawItem& item : items) {
      glUniformMatrix4fv(u.model, 1, GL_FALSE, glm::value_ptr(item.model));
      for (const render::GpuPrimitive& p : item.mesh->primitives) {
        const render::GpuMaterial& m =
            scene_.material(item.material_override >= 0 ? item.material_override : p.material);
        if (m.alpha_mode == AlphaMode::Blend || (m.alpha_mode == AlphaMode::Mask) != cut_out) continue;
        if (cut_out) render::bind_alpha_test(m, m.alpha_cutoff, u.material);
        // Same culling as the shading pass, so both passes see the same surfaces.
        if (m.double_sided)
          glDisable(GL_CULL_FACE);
        else
          glEnable(GL_CULL_FACE);
        glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                                 p.base_vertex);
      }
    }
  }
  render::unbind_material_samplers();
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_STENCIL_TEST);
}

}  // namespace engine::render
