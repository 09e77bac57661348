// engine::render::ForwardRenderer's half-resolution area shadows (RenderSettings::area_shadow_res):
// the area lights' soft-shadow visibility at half resolution, lent to the full-resolution
// pixels on the same surface (area_shadow.frag.glsl).
#include "render/forward_renderer.h"

#include <cstdio>
#include <glm/gtc/type_ptr.hpp>
#include <engine/check.h>

namespace engine::render {

namespace {

// One pass of the half-resolution area shadows (area_shadow.frag.glsl) for `area_lights` lights.
Result<ShaderProgram> build_area_shadow(int pass, int area_lights) {
  return ShaderProgramBuilder(engine_shader_files())
      .stage(ShaderStage::Vertex, "forward.vert.glsl")
      .stage(ShaderStage::Fragment, "area_shadow.frag.glsl")
      .define("AREA_SHADOW_PASS " + std::to_string(pass))
      .define("AREA_LIGHTS " + std::to_string(area_lights))
      .build();
}

}  // namespace

const ShaderProgram& ForwardRenderer::area_shadow_program(int pass, int area_lights) {
  const std::pair<int, int> key(pass, area_lights);
  auto it = area_shadow_programs_.find(key);
  if (it != area_shadow_programs_.end()) return it->second;
  Result<ShaderProgram> p = build_area_shadow(pass, area_lights);
  if (!p) std::fprintf(stderr, "%s\n", p.error().to_string().c_str());
  GI_EXPECTS(p.ok(), "area shadow shader must compile");
  return area_shadow_programs_.emplace(key, std::move(p.value())).first->second;
}

// Every item's primitives with the pre-pass's culling (double-sided materials both faces);
// with `double_sided_uniform`, location 26 says which (area_shadow.frag.glsl flips the normal).
// BLEND primitives are left out (they write no depth; they read the visibility of the surface
// behind them). Without `double_sided_uniform` this is the half-resolution depth pass: MASK
// primitives are drawn last with the alpha-tested depth program at `view_proj`.
void ForwardRenderer::draw_geometry(const std::vector<DrawItem>& items, bool double_sided_uniform,
                                    const glm::mat4& view_proj) {
  const bool depth_pass = !double_sided_uniform;
  for (const bool cut_out : {false, true}) {
    if (cut_out) {
      if (!depth_pass || !scene_.has_mask()) break;
      alpha_test_program("depth_only.frag.glsl").use();
      glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(view_proj));
    }
    for (const DrawItem& item : items) {
      glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(item.model));
      if (double_sided_uniform) {
        const glm::mat4 normal_matrix(glm::transpose(glm::inverse(glm::mat3(item.model))));
        glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(normal_matrix));
        glUniform1i(12, item.mesh->first_vertex);
      }
      for (const render::GpuPrimitive& p : item.mesh->primitives) {
        const render::GpuMaterial& m =
            scene_.material(item.material_override >= 0 ? item.material_override : p.material);
        if (m.alpha_mode == AlphaMode::Blend) continue;
        if (depth_pass && (m.alpha_mode == AlphaMode::Mask) != cut_out) continue;
        if (cut_out) render::bind_alpha_test(m, m.alpha_cutoff);
        if (m.double_sided)
          glDisable(GL_CULL_FACE);
        else
          glEnable(GL_CULL_FACE);
        if (double_sided_uniform) glUniform1i(26, m.double_sided ? 1 : 0);
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
  const auto common_uniforms = [&](const ShaderProgram& program) {
    program.use();
    glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(view_proj));
    glUniform3fv(16, 1, glm::value_ptr(camera_position));
    glUniform1i(13, 0);  // forward.vert.glsl: no vertex irradiance, no lobes
    glUniform1i(40, 0);
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
  glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(view_proj));
  draw_geometry(items, false, view_proj);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  common_uniforms(area_shadow_program(0, n));
  draw_geometry(items, true, view_proj);
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
  common_uniforms(area_shadow_program(1, n));
  draw_geometry(items, true, view_proj);
  // 3. The flagged pixels at full resolution (the stencil rejects the others before shading).
  glStencilMask(0);
  glStencilFunc(GL_EQUAL, static_cast<GLint>(kAreaFallbackBit), kAreaFallbackBit);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  common_uniforms(area_shadow_program(2, n));
  draw_geometry(items, true, view_proj);
  glDisable(GL_STENCIL_TEST);
  glStencilMask(0xFF);
}

}  // namespace engine::render
