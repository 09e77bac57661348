// engine::render::ForwardRenderer's half-resolution area shadows (RenderSettings::area_shadow_res):
// the area lights' soft-shadow visibility at half resolution, lent to the full-resolution
// pixels on the same surface (area_shadow.frag.glsl).
#include "render/forward_renderer.h"

#include <cstdio>
#include <glm/gtc/type_ptr.hpp>
#include <engine/check.h>
#include <engine/log.h>

namespace engine::render {

namespace {

// One pass of the half-resolution area shadows (area_shadow.frag.glsl) for `area_lights` lights.
Result<LocatedProgram<AreaShadowUniforms>> build_area_shadow(int pass, int area_lights) {
  ShaderProgramBuilder b(engine_shader_files());
  b.define("AREA_SHADOW_PASS " + std::to_string(pass)).define("AREA_LIGHTS " + std::to_string(area_lights));
  return link_program<AreaShadowUniforms>(
      std::move(b), {{ShaderStage::Vertex, "forward.vert.glsl"}, {ShaderStage::Fragment, "area_shadow.frag.glsl"}});
}

}  // namespace

const LocatedProgram<AreaShadowUniforms>& ForwardRenderer::area_shadow_program(int pass, int area_lights) {
  const std::pair<int, int> key(pass, area_lights);
  auto it = area_shadow_programs_.find(key);
  if (it != area_shadow_programs_.end()) return it->second;
  Result<LocatedProgram<AreaShadowUniforms>> p = build_area_shadow(pass, area_lights);
  if (!p) log_message(LogLevel::Error, p.error().to_string());
  GI_EXPECTS(p.ok(), "area shadow shader must compile");
  return area_shadow_programs_.emplace(key, std::move(p.value())).first->second;
}

// Every item's primitives with the pre-pass's culling (double-sided materials both faces);
// with `shading`, its u_double_sided says which (area_shadow.frag.glsl flips the normal).
// BLEND primitives are left out (they write no depth; they read the visibility of the surface
// behind them). Without `shading` this is the half-resolution depth pass (depth_only_): MASK
// primitives are drawn last with the alpha-tested depth program at `view_proj`.
void ForwardRenderer::draw_geometry(const std::vector<DrawItem>& items,
                                    const LocatedProgram<AreaShadowUniforms>* shading, const glm::mat4& view_proj) {
  const bool depth_pass = shading == nullptr;
  for (const bool cut_out : {false, true}) {
    const LocatedProgram<DepthUniforms>* depth = depth_pass ? &depth_only_ : nullptr;
    if (cut_out) {
      if (!depth_pass || !scene_.has_mask()) break;
      depth = &alpha_test_program("depth_only.frag.glsl");
      depth->use();
      glUniformMatrix4fv(depth->uniforms.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
    }
    for (const DrawItem& item : items) {
      glUniformMatrix4fv(depth_pass ? depth->uniforms.model : shading->uniforms.model, 1, GL_FALSE,
                         glm::value_ptr(item.model));
      if (!depth_pass) {
        const glm::mat4 normal_matrix(glm::transpose(glm::inverse(glm::mat3(item.model))));
        glUniformMatrix4fv(shading->uniforms.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
        glUniform1i(shading->uniforms.mesh_first_vertex, item.mesh->first_vertex);
      }
      for (const render::GpuPrimitive& p : item.mesh->primitives) {
        const render::GpuMaterial& m =
            scene_.material(item.material_override >= 0 ? item.material_override : p.material);
        if (m.alpha_mode == AlphaMode::Blend) continue;
        if (depth_pass && (m.alpha_mode == AlphaMode::Mask) != cut_out) continue;
        if (cut_out) render::bind_alpha_test(m, m.alpha_cutoff, depth->uniforms.material);
        if (m.double_sided)
          glDisable(GL_CULL_FACE);
        else
          glEnable(GL_CULL_FACE);
        if (!depth_pass) glUniform1i(shading->uniforms.double_sided, m.double_sided ? 1 : 0);
        glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                                 p.base_vertex);
      }
    }
  }
  if (depth_pass) render::unbind_material_samplers();
}

// The area lights' soft-shadow visibility at half resolution, upsampled where the surface
// matches and computed at full resolution where it does not (area_shadow.frag.glsl), into
// area_visibility_ for the forward pass. Needs the full-resolution depth pre-pass done.
void ForwardRenderer::area_shadow_passes(const glm::mat4& view_proj, const glm::vec3& camera_position,
                                         const std::vector<DrawItem>& items) {
  const int n = static_cast<int>(area_lights_.size());
  glNamedBufferData(area_lights_buffer_.id(), static_cast<GLsizeiptr>(area_lights_.size() * sizeof(render::GpuLight)),
                    area_lights_.data(), GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLightsBinding, area_lights_buffer_.id());
  glBindTextureUnit(kShadowMapsUnit, shadow_maps_.maps_2d());
  glBindTextureUnit(kPointShadowMapsUnit, shadow_maps_.cube_maps());
  glBindTextureUnit(kShadowDepthUnit, shadow_maps_.maps_2d());
  glBindSampler(kShadowDepthUnit, shadow_depth_sampler_.id());
  const auto common_uniforms = [&](const LocatedProgram<AreaShadowUniforms>& program) {
    program.use();
    glUniformMatrix4fv(program.uniforms.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
    glUniform3fv(program.uniforms.camera_position, 1, glm::value_ptr(camera_position));
    glUniform1i(program.uniforms.use_vertex_irradiance, 0);  // forward.vert.glsl: no vertex irradiance, no lobes
    glUniform1i(program.uniforms.lobe_terms, 0);
    return &program;
  };
  // 1. Half resolution: depth, then each surface's visibility and tangent plane.
  const int half_w = (width_ + 1) / 2;
  const int half_h = (height_ + 1) / 2;
  glBindFramebuffer(GL_FRAMEBUFFER, half_fbo_.id());
  glViewport(0, 0, half_w, half_h);
  const float one = 1.0f;
  const float unlit[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  const float no_plane[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // a zero normal matches no pixel
  glClearNamedFramebufferfv(half_fbo_.id(), GL_DEPTH, 0, &one);
  glClearNamedFramebufferfv(half_fbo_.id(), GL_COLOR, 0, unlit);
  glClearNamedFramebufferfv(half_fbo_.id(), GL_COLOR, 1, no_plane);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  depth_only_.use();
  glUniformMatrix4fv(depth_only_.uniforms.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
  draw_geometry(items, nullptr, view_proj);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  draw_geometry(items, common_uniforms(area_shadow_program(0, n)), view_proj);
  // 2. Full resolution on the pre-pass's depth: upsample, flagging the pixels no half-resolution
  // texel of their own surface covers in the stencil's top bit (the reach masks keep theirs).
  glBindFramebuffer(GL_FRAMEBUFFER, visibility_fbo_.id());
  glViewport(0, 0, width_, height_);
  glBindTextureUnit(kAreaVisibilityUnit, half_visibility_.id());
  glBindTextureUnit(kAreaPlaneUnit, half_plane_.id());
  glEnable(GL_STENCIL_TEST);
  glStencilMask(kAreaFallbackBit);
  glStencilFunc(GL_ALWAYS, 0, 0xFF);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  draw_geometry(items, common_uniforms(area_shadow_program(1, n)), view_proj);
  // 3. The flagged pixels at full resolution (the stencil rejects the others before shading).
  glStencilMask(0);
  glStencilFunc(GL_EQUAL, static_cast<GLint>(kAreaFallbackBit), kAreaFallbackBit);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  draw_geometry(items, common_uniforms(area_shadow_program(2, n)), view_proj);
  glDisable(GL_STENCIL_TEST);
  glStencilMask(0xFF);
}

}  // namespace engine::render
