// engine::render::ForwardRenderer's forward pass: the program variants (one per light counts),
// what the pass reads (shadow maps, the provider's frame, the BRDF table), the uniforms of the
// frame and of each item, and the drawing of each light group's pixels, then of the BLEND
// primitives back to front.
#include "render/forward_renderer.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <utility>

#include <GL/glcorearb.h>
#include <glm/gtc/type_ptr.hpp>

#include <engine/check.h>
#include <engine/components.h>
#include <engine/gpu/shader_program.h>
#include <engine/log.h>

#include "render/gpu_scene.h"

namespace engine::render {

namespace {

enum IndirectMode : int { kIndirectNone = 0, kIndirectAmbient = 1, kIndirectAtlas = 2, kIndirectVertex = 3 };

// A dielectric whose roughness is at least kRoughForOnePoint everywhere (no roughness texture):
// its GGX lobe is far wider than the spread of directions to an area light's points, so one
// specular point per rectangle (the centre) gives its radiance within about 1% (1.02% worst
// at roughness 0.9, RendererAreaLight.RoughDielectricsTakeOneSpecularPoint).
constexpr float kRoughForOnePoint = 0.9f;
bool rough_dielectric(const render::GpuMaterial& m, GLuint white_texture) {
  return m.metallic == 0.0f && m.roughness >= kRoughForOnePoint && m.metallic_roughness_texture == white_texture;
}

// A material whose roughness is below kSharpForLtc everywhere (no roughness texture): with
// RenderSettings::area_specular_samples_per_side 0 it draws area lights' specular from the
// fitted linearly transformed cosines (AREA_SPECULAR_SIDE 0), which follow its sharp lobe
// where points split it into separate highlights; wider lobes take 3 x 3 points, which the
// fit does not match at grazing views (RendererAreaSpecular measures both).
constexpr float kSharpForLtc = 0.3f;
bool sharp_for_ltc(const render::GpuMaterial& m, GLuint white_texture) {
  return m.roughness < kSharpForLtc && m.metallic_roughness_texture == white_texture;
}

// A provider's SSBO of `Element`s at `binding`, where the engine's shaders declare that element.
template <class Element>
void bind_ssbo(GLuint binding, SsboHandle<Element> buffer) {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer.gl_name);
}

}  // namespace

Result<LocatedProgram<ForwardUniforms>> build_forward_program(const LightCounts& counts) {
  ShaderProgramBuilder b(engine_shader_files());
  b.define("POINT_LIGHTS " + std::to_string(counts[0]))
      .define("SPOT_LIGHTS " + std::to_string(counts[1]))
      .define("DIRECTIONAL_LIGHTS " + std::to_string(counts[2]))
      .define("AREA_LIGHTS " + std::to_string(counts[3]))
      .define("AREA_SPECULAR_SIDE " + std::to_string(counts[4]))
      .define("AREA_SOFT_SHADOWS " + std::to_string(counts[5]))
      .define("SKY_TERM " + std::to_string(counts[6]))
      .define("AREA_SHADOW_HALF " + std::to_string(counts[7]))
      .define("FLAT_SHADING " + std::to_string(counts[8]));
  return link_program<ForwardUniforms>(
      std::move(b), {{ShaderStage::Vertex, "forward.vert.glsl"}, {ShaderStage::Fragment, "forward.frag.glsl"}});
}

const LocatedProgram<ForwardUniforms>& ForwardRenderer::forward_program(const LightCounts& counts) {
  auto it = forward_variants_.find(counts);
  if (it != forward_variants_.end()) return it->second;
  Result<LocatedProgram<ForwardUniforms>> p = build_forward_program(counts);
  // The variant without lights compiled in create(); a failure here is a shader bug.
  if (!p) log_message(LogLevel::Error, p.error().to_string());
  GI_EXPECTS(p.ok(), "forward shader variant must compile");
  return forward_variants_.emplace(counts, std::move(p.value())).first->second;
}

// The shadow maps, the provider's textures and buffers and the BRDF table on their units.
ForwardRenderer::ForwardInputs ForwardRenderer::bind_forward_inputs(const IndirectLightFrame* indirect) {
  glBindTextureUnit(kShadowMapsUnit, shadow_maps_.maps_2d());
  glBindTextureUnit(kPointShadowMapsUnit, shadow_maps_.cube_maps());
  glBindTextureUnit(kShadowDepthUnit, shadow_maps_.maps_2d());
  glBindSampler(kShadowDepthUnit, shadow_depth_sampler_.id());
  glBindTextureUnit(kSunShadowMapsUnit, shadow_maps_.sun_maps());
  glBindTextureUnit(kSunShadowDepthUnit, shadow_maps_.sun_maps());
  glBindSampler(kSunShadowDepthUnit, shadow_depth_sampler_.id());
  ForwardInputs in;
  in.indirect = indirect;
  in.atlas = indirect ? indirect->irradiance_atlas_texture.gl_name : 0;
  in.glossy = indirect ? indirect->glossy_radiance_texture.gl_name : 0;
  glBindTextureUnit(kIrradianceAtlasUnit, in.atlas != 0 ? in.atlas : scene_.white_texture());
  glBindTextureUnit(kGlossyUnit, in.glossy != 0 ? in.glossy : scene_.white_texture());
  glBindTextureUnit(kGltfAlbedoTableUnit, albedo_table_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kAreaLtcBinding, area_ltc_table_.id());
  // Directional radiance of static surfaces (IndirectLightFrame::directional_*), when provided.
  in.directional = indirect != nullptr && indirect->directional_index_texture &&
                   indirect->directional_radiance_buffer && indirect->directional_direction_buffer &&
                   indirect->directional_bin_count > 0 && indirect->directional_element_count > 0;
  glBindTextureUnit(kDirectionalIndexUnit,
                    in.directional ? indirect->directional_index_texture.gl_name : no_directional_index_.id());
  if (in.directional) {
    bind_ssbo(kDirectionalRadianceBinding, indirect->directional_radiance_buffer);
    bind_ssbo(kDirectionalDirectionBinding, indirect->directional_direction_buffer);
  }
  // Reflection probes (IndirectLightFrame::reflection_probe_*), when provided.
  in.probes = indirect != nullptr && indirect->reflection_probe_cubes && indirect->reflection_probe_buffer &&
              indirect->reflection_probe_count > 0 && indirect->reflection_probe_levels > 0;
  if (in.probes) {
    glBindTextureUnit(kReflectionProbeUnit, indirect->reflection_probe_cubes.gl_name);
    if (indirect->reflection_probe_distances)
      glBindTextureUnit(kReflectionProbeDistanceUnit, indirect->reflection_probe_distances.gl_name);
    bind_ssbo(kReflectionProbeBinding, indirect->reflection_probe_buffer);
  }
  const SkyGradient& sky = settings_.sky_gradient;
  const glm::vec3 zero(0.0f);
  in.has_sky = glm::any(glm::notEqual(settings_.sky_radiance, zero)) || glm::any(glm::notEqual(sky.horizon, zero)) ||
               glm::any(glm::notEqual(sky.zenith, zero)) || glm::any(glm::notEqual(sky.ground, zero));
  return in;
}

// The uniforms every item of a forward program's pass shares.
void ForwardRenderer::set_forward_frame_uniforms(const ForwardUniforms& u, const ForwardInputs& in, bool blend) {
  glUniform1i(u.directional_bins, in.directional ? in.indirect->directional_bin_count : 0);
  glUniform1i(u.directional_elements, in.directional ? in.indirect->directional_element_count : 0);
  glUniform1i(u.directional_tangent_frame, in.directional && in.indirect->directional_tangent_frame ? 1 : 0);
  glUniform1i(u.probe_count, in.probes ? in.indirect->reflection_probe_count : 0);
  glUniform1i(u.probe_levels, in.probes ? in.indirect->reflection_probe_levels : 0);
  glUniform1i(u.probe_has_distances, in.probes && in.indirect->reflection_probe_distances ? 1 : 0);
  glUniform1f(u.probe_max_roughness, in.probes ? in.indirect->reflection_probe_max_roughness : 0.0f);
  glUniform1i(u.probe_lobe_samples, in.probes ? in.indirect->reflection_probe_lobe_samples : 0);
  glUniform1i(u.probe_lobe_samples_max, in.probes ? in.indirect->reflection_probe_lobe_samples_max : 0);
  glUniformMatrix4fv(u.view_proj, 1, GL_FALSE, glm::value_ptr(in.view->view_proj));
  glUniform3fv(u.camera_position, 1, glm::value_ptr(in.view->position));
  glUniform1f(u.ambient_radiance, settings_.stand_in_ambient);
  glUniform3fv(u.sky_radiance, 1, glm::value_ptr(settings_.sky_radiance));
  {  // The sky's gradient (engine/sky.h): horizon, zenith - horizon, ground - horizon.
    const SkyGradient& g = settings_.sky_gradient;
    const glm::vec3 terms[3] = {g.horizon, g.zenith - g.horizon, g.ground - g.horizon};
    glUniform3fv(u.sky_gradient, 3, glm::value_ptr(terms[0]));
  }
  glUniform1f(u.split_x, settings_.split == SplitView::DirectLeftFullRight ? 0.5f * static_cast<float>(width_) : -1.0f);
  glUniform1i(u.use_glossy, in.glossy != 0 && !blend ? 1 : 0);  // the glossy texture is the opaque surface's
}

// Where `item`'s indirect light comes from (the atlas for static items, the provider's
// per-vertex buffers for dynamic ones, the stand-in without a provider), its sky occlusion
// and what its atlas holds besides indirect light; binds its buffers and sets the uniforms.
void ForwardRenderer::set_item_indirect(const ForwardUniforms& u, const DrawItem& item, const ForwardInputs& in) {
  const IndirectLightFrame* indirect = in.indirect;
  int mode = kIndirectAmbient;
  SsboHandle<VertexIrradiance> vertex_buffer;
  if (indirect != nullptr) {
    mode = kIndirectNone;
    if (item.is_static && in.atlas != 0) {
      mode = kIndirectAtlas;
    } else if (!item.is_static) {
      vertex_buffer = indirect->vertex_irradiance_buffer(item.entity);
      if (vertex_buffer) mode = kIndirectVertex;
    }
  }
  {  // The sky's occlusion on a dynamic entity, when the provider measured it (indirect_light.h).
    float axes[6] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    if (indirect != nullptr && !item.is_static) (void)indirect->sky_visibility(item.entity, axes);
    glUniform3f(u.sky_visibility_pos, axes[0], axes[2], axes[4]);
    glUniform3f(u.sky_visibility_neg, axes[1], axes[3], axes[5]);
  }
  // What the atlas this item reads holds besides indirect light (not drawn again here).
  const bool baked = mode == kIndirectAtlas;
  glUniform1i(u.baked_direct,
              (baked && indirect->atlas_holds_sky ? 1 : 0) | (baked && indirect->atlas_holds_static_lights ? 2 : 0));
  if (vertex_buffer) bind_ssbo(kVertexIrradianceBinding, vertex_buffer);
  // Per-vertex view-dependent indirect light (IndirectLightFrame::vertex_radiance_lobes).
  IndirectLightFrame::VertexRadianceLobes lobes;
  if (vertex_buffer) lobes = indirect->vertex_radiance_lobes(item.entity);
  const bool use_lobes = lobes.terms > 0 && lobes.resolution > 0 && lobes.coefficient_buffer && lobes.lobe_buffer &&
                         lobes.first >= 0 && lobes.stride >= 0;
  if (use_lobes) {
    bind_ssbo(kLobeCoefficientsBinding, lobes.coefficient_buffer);
    bind_ssbo(kLobeTableBinding, lobes.lobe_buffer);
  }
  glUniform1i(u.lobe_terms, use_lobes ? lobes.terms : 0);
  glUniform1i(u.lobe_resolution, lobes.resolution);
  glUniform1i(u.lobe_first, lobes.first);
  glUniform1i(u.lobe_stride, lobes.stride);
  glUniform1i(u.mesh_first_vertex, item.mesh->first_vertex);
  glUniform1i(u.use_vertex_irradiance, vertex_buffer ? 1 : 0);
  glUniform1i(u.indirect_mode, mode);
}

// One primitive with its material (factors, textures, samplers, culling).
void ForwardRenderer::draw_shaded_primitive(const ForwardUniforms& u, const GpuMaterial& m, const GpuPrimitive& p) {
  if (m.double_sided)
    glDisable(GL_CULL_FACE);
  else
    glEnable(GL_CULL_FACE);
  glUniform4fv(u.base_color, 1, glm::value_ptr(m.base_color));
  glUniform1f(u.metallic, m.metallic);
  glUniform1f(u.roughness, m.roughness);
  glUniform3fv(u.emissive, 1, glm::value_ptr(m.emissive));
  glUniform1i(u.double_sided, m.double_sided ? 1 : 0);
  glUniform1f(u.specular_factor, m.specular_factor);
  glUniform3fv(u.specular_color_factor, 1, glm::value_ptr(m.specular_color_factor));
  glBindTextureUnit(kBaseColorUnit, m.base_color_texture);
  glBindTextureUnit(kMetallicRoughnessUnit, m.metallic_roughness_texture);
  glBindTextureUnit(kEmissiveUnit, m.emissive_texture);
  glBindTextureUnit(kNormalUnit, m.normal_texture != 0 ? m.normal_texture : scene_.white_texture());
  glBindSampler(kBaseColorUnit, m.samplers[render::kBaseColorSlot]);
  glBindSampler(kMetallicRoughnessUnit, m.samplers[render::kMetallicRoughnessSlot]);
  glBindSampler(kEmissiveUnit, m.samplers[render::kEmissiveSlot]);
  glBindSampler(kNormalUnit, m.samplers[render::kNormalSlot]);
  render::set_material_texturing(m, u.material);
  glUniform1f(u.normal_scale, m.normal_scale);
  glUniform1i(u.normal_map, m.normal_texture != 0 ? 1 : 0);
  glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                           p.base_vertex);
}

// One light group's pixels (its stencil mask), or with `blend` the BLEND primitives of
// `order` (back to front) over everything, without the stencil.
// Long because the passes (one per area-specular variant in use) and the scan that finds
// the variants share the group's counts and the material rules (side_of, in_group): split,
// each part would take all of them.
void ForwardRenderer::shade_group(const ForwardInputs& in, const LightGroup& group,
                                  const std::vector<const DrawItem*>& order, bool blend) {
  if (in.reach && !blend) glStencilFunc(GL_EQUAL, group.mask, area_lights_.empty() ? 0xFF : 0xFF & ~kAreaFallbackBit);
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kLightsBinding, lights_buffer_.id(), group.offset,
                    static_cast<GLsizeiptr>(std::max<std::size_t>(1, group.lights.size()) * sizeof(render::GpuLight)));
  const int setting = std::clamp(settings_.area_specular_samples_per_side, 0, 4);
  // (BLEND primitives draw in one pass, in back-to-front order: with setting 0, 3 x 3 points.)
  const LightCounts counts{group.count_by_type[0],
                           group.count_by_type[1],
                           group.count_by_type[2],
                           group.count_by_type[3],
                           blend && setting == 0 && group.count_by_type[3] > 0 ? 3 : setting,
                           settings_.area_soft_shadows ? 1 : 0,
                           in.has_sky ? 1 : 0,
                           area_lights_.empty() ? 0 : 1,
                           settings_.flat_shading ? 1 : 0};
  // The area-light specular variant (LightCounts[4]) each material draws with: rough
  // dielectrics one point (rough_dielectric), with setting 0 sharp materials the fitted
  // transforms (sharp_for_ltc) and the others 3 x 3 points, else the setting's points. One
  // pass over the items per variant in use, each with its program.
  const GLuint white = scene_.white_texture();
  const auto side_of = [&](const render::GpuMaterial& m) {
    if (blend || counts[3] == 0) return counts[4];
    if (settings_.area_specular_one_point_on_rough && setting != 1 && rough_dielectric(m, white)) return 1;
    if (setting != 0) return setting;
    return sharp_for_ltc(m, white) ? 0 : 3;
  };
  const auto material_of = [&](const DrawItem& item, const render::GpuPrimitive& p) -> const render::GpuMaterial& {
    return scene_.material(item.material_override >= 0 ? item.material_override : p.material);
  };
  const auto in_group = [&](const DrawItem& item) {
    const render::SceneBounds& gb = group.bounds;
    return gb.empty ||
           !(glm::any(glm::lessThan(item.bounds.max, gb.min)) || glm::any(glm::greaterThan(item.bounds.min, gb.max)));
  };
  std::array<bool, 5> used{};
  for (const DrawItem* drawn : order) {
    if (!in_group(*drawn)) continue;
    for (const render::GpuPrimitive& p : drawn->mesh->primitives) {
      const render::GpuMaterial& m = material_of(*drawn, p);
      if ((m.alpha_mode == AlphaMode::Blend) == blend) used[static_cast<std::size_t>(side_of(m))] = true;
    }
  }
  for (int side = 0; side < 5; ++side) {
    if (!used[static_cast<std::size_t>(side)]) continue;
    LightCounts pass_counts = counts;
    pass_counts[4] = side;
    const LocatedProgram<ForwardUniforms>& program = forward_program(pass_counts);
    const ForwardUniforms& u = program.uniforms;
    program.use();
    set_forward_frame_uniforms(u, in, blend);
    const auto in_pass = [&](const DrawItem& item, const render::GpuPrimitive& p) {
      const render::GpuMaterial& m = material_of(item, p);
      return (m.alpha_mode == AlphaMode::Blend) == blend && side_of(m) == side;
    };
    for (const DrawItem* drawn : order) {
      const DrawItem& item = *drawn;
      if (!in_group(item)) continue;  // none of this group's pixels can be on the item
      if (std::none_of(item.mesh->primitives.begin(), item.mesh->primitives.end(),
                       [&](const render::GpuPrimitive& p) { return in_pass(item, p); }))
        continue;
      set_item_indirect(u, item, in);
      glUniformMatrix4fv(u.model, 1, GL_FALSE, glm::value_ptr(item.model));
      const glm::mat4 normal_matrix(glm::transpose(glm::inverse(glm::mat3(item.model))));
      glUniformMatrix4fv(u.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
      for (const render::GpuPrimitive& p : item.mesh->primitives) {
        if (!in_pass(item, p)) continue;
        draw_shaded_primitive(u, material_of(item, p), p);
      }
    }
  }
}

// BLEND: after every opaque pixel, back to front by the item's centre, blended over what is
// there ("over": alpha x colour + (1 - alpha) x behind; the target's alpha is kept), tested
// against the pre-pass's depth but not writing it. Every pixel of a blended surface is lit
// by the group of all lights (the reach stencil holds the surface behind it).
void ForwardRenderer::shade_blended(const ForwardInputs& in, const std::vector<DrawItem>& items,
                                    const std::vector<LightGroup>& groups) {
  std::vector<std::pair<float, const DrawItem*>> blended;
  for (const DrawItem& item : items)
    for (const render::GpuPrimitive& p : item.mesh->primitives)
      if (scene_.material(item.material_override >= 0 ? item.material_override : p.material).alpha_mode ==
          AlphaMode::Blend) {
        const glm::vec3 centre = 0.5f * (item.bounds.min + item.bounds.max);
        blended.emplace_back(glm::length(centre - in.view->position), &item);
        break;
      }
  if (blended.empty()) return;
  std::stable_sort(blended.begin(), blended.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<const DrawItem*> back_to_front;
  for (const auto& [distance, item] : blended) back_to_front.push_back(item);
  const auto all = std::find_if(groups.begin(), groups.end(),
                                [&](const LightGroup& g) { return !in.reach || g.mask == reach_.grid.all; });
  glDisable(GL_STENCIL_TEST);
  glDepthFunc(GL_LESS);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  if (all != groups.end()) shade_group(in, *all, back_to_front, true);
  glDisable(GL_BLEND);
}

void ForwardRenderer::forward_pass(const CameraView& view, const std::vector<DrawItem>& items,
                                   const std::vector<LightGroup>& groups, const IndirectLightFrame* indirect) {
  const bool reach = !groups.empty() && groups.front().mask >= 0;
  begin_forward_pass(view, items, reach);
  ForwardInputs in = bind_forward_inputs(indirect);
  in.view = &view;
  in.reach = reach;
  std::vector<const DrawItem*> in_order;
  for (const DrawItem& item : items) in_order.push_back(&item);
  for (const LightGroup& group : groups) shade_group(in, group, in_order, false);
  shade_blended(in, items, groups);
  unbind_material_samplers();
  glDisable(GL_STENCIL_TEST);
  glStencilMask(0xFF);
  glDisable(GL_CULL_FACE);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace engine::render
