// engine::Renderer: shadow maps, a forward linear-HDR pass (RGBA16F + depth), then
// exposure, ACES-fitted tonemap and sRGB encoding into an RGBA8 target. The class is declared
// in render/forward_renderer.h; its light reach and half-resolution area shadows live in
// forward_reach.cpp and forward_area_shadow.cpp.
#include "render/forward_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <utility>

#include <GL/glcorearb.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <engine/components.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gltf_brdf_texture.h>
#include <engine/gpu/gpu_timer.h>
#include <engine/gpu/shader_program.h>
#include <engine/light_reach.h>
#include <engine/log.h>
#include <engine/runtime_limits.h>

#include "render/frame_data.h"
#include "render/gpu_scene.h"
#include "render/light_list.h"
#include "render/shadow_maps.h"

namespace engine::render {

GlSampler raw_depth_sampler() {
  GlSampler s = GlSampler::create();
  glSamplerParameteri(s.id(), GL_TEXTURE_COMPARE_MODE, GL_NONE);
  glSamplerParameteri(s.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glSamplerParameteri(s.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return s;
}

GlTexture no_directional_index() {
  GlTexture t = GlTexture::create_2d(GL_R32I, 1, 1);
  const GLint none = -1;
  glTextureSubImage2D(t.id(), 0, 0, 0, 1, 1, GL_RED_INTEGER, GL_INT, &none);
  glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return t;
}

namespace {

enum IndirectMode : int { kIndirectNone = 0, kIndirectAmbient = 1, kIndirectAtlas = 2, kIndirectVertex = 3 };

Result<LocatedProgram<DepthUniforms>> build_depth(const char* fragment) {
  return link_program<DepthUniforms>(ShaderProgramBuilder(engine_shader_files()),
                                     {{ShaderStage::Vertex, "shadow.vert.glsl"}, {ShaderStage::Fragment, fragment}});
}

// The forward program for one combination of light counts (see forward.frag.glsl).
Result<LocatedProgram<ForwardUniforms>> build_forward(const LightCounts& n) {
  ShaderProgramBuilder b(engine_shader_files());
  b.define("POINT_LIGHTS " + std::to_string(n[0]))
      .define("SPOT_LIGHTS " + std::to_string(n[1]))
      .define("DIRECTIONAL_LIGHTS " + std::to_string(n[2]))
      .define("AREA_LIGHTS " + std::to_string(n[3]))
      .define("AREA_SPECULAR_SIDE " + std::to_string(n[4]))
      .define("AREA_SOFT_SHADOWS " + std::to_string(n[5]))
      .define("SKY_TERM " + std::to_string(n[6]))
      .define("AREA_SHADOW_HALF " + std::to_string(n[7]))
      .define("FLAT_SHADING " + std::to_string(n[8]));
  return link_program<ForwardUniforms>(
      std::move(b), {{ShaderStage::Vertex, "forward.vert.glsl"}, {ShaderStage::Fragment, "forward.frag.glsl"}});
}

// A dielectric whose roughness is at least kRoughForOnePoint everywhere (no roughness texture):
// its GGX lobe is far wider than the spread of directions to an area light's points, so one
// specular point per rectangle (the centre) gives its radiance within about 1% (1.02% worst
// at roughness 0.9, RendererAreaLight.RoughDielectricsTakeOneSpecularPoint).
constexpr float kRoughForOnePoint = 0.9f;
bool rough_dielectric(const render::GpuMaterial& m, GLuint white_texture) {
  return m.metallic == 0.0f && m.roughness >= kRoughForOnePoint && m.metallic_roughness_texture == white_texture;
}

// A provider's SSBO of `Element`s at `binding`, where the engine's shaders declare that element.
template <class Element>
void bind_ssbo(GLuint binding, SsboHandle<Element> buffer) {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer.gl_name);
}

}  // namespace

const LocatedProgram<ForwardUniforms>& ForwardRenderer::forward_program(const LightCounts& counts) {
  auto it = forward_variants_.find(counts);
  if (it != forward_variants_.end()) return it->second;
  Result<LocatedProgram<ForwardUniforms>> p = build_forward(counts);
  // The variant without lights compiled in create(); a failure here is a shader bug.
  if (!p) log_message(LogLevel::Error, p.error().to_string());
  GI_EXPECTS(p.ok(), "forward shader variant must compile");
  return forward_variants_.emplace(counts, std::move(p.value())).first->second;
}

void ForwardRenderer::ensure_targets() {
  GI_EXPECTS(settings_.width > 0 && settings_.height > 0, "render size must be positive");
  if (settings_.width == width_ && settings_.height == height_ && !hdr_.empty()) return;
  width_ = settings_.width;
  height_ = settings_.height;
  hdr_ = GlTexture::create_2d(GL_RGBA16F, width_, height_);
  depth_ = GlTexture::create_2d(GL_DEPTH32F_STENCIL8, width_, height_);  // stencil: light reach masks
  ldr_ = GlTexture::create_2d(GL_RGBA8, width_, height_);
  for (GLuint t : {hdr_.id(), ldr_.id()}) {
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  hdr_fbo_ = GlFramebuffer::create();
  glNamedFramebufferTexture(hdr_fbo_.id(), GL_COLOR_ATTACHMENT0, hdr_.id(), 0);
  glNamedFramebufferTexture(hdr_fbo_.id(), GL_DEPTH_STENCIL_ATTACHMENT, depth_.id(), 0);
  ldr_fbo_ = GlFramebuffer::create();
  glNamedFramebufferTexture(ldr_fbo_.id(), GL_COLOR_ATTACHMENT0, ldr_.id(), 0);
  GI_EXPECTS(hdr_fbo_.complete() && ldr_fbo_.complete(), "render targets must be complete");
  // Half-resolution area shadows (area_shadow.frag.glsl): made with the other targets, used
  // only when RenderSettings::area_shadow_res is Half.
  const int half_w = (width_ + 1) / 2;
  const int half_h = (height_ + 1) / 2;
  half_depth_ = GlTexture::create_2d(GL_DEPTH_COMPONENT32F, half_w, half_h);
  half_visibility_ = GlTexture::create_2d(GL_RGBA16F, half_w, half_h);
  half_plane_ = GlTexture::create_2d(GL_RGBA32F, half_w, half_h);
  area_visibility_ = GlTexture::create_2d(GL_RGBA16F, width_, height_);
  for (GLuint t : {half_visibility_.id(), half_plane_.id(), area_visibility_.id()}) {
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  half_fbo_ = GlFramebuffer::create();
  glNamedFramebufferTexture(half_fbo_.id(), GL_COLOR_ATTACHMENT0, half_visibility_.id(), 0);
  glNamedFramebufferTexture(half_fbo_.id(), GL_COLOR_ATTACHMENT1, half_plane_.id(), 0);
  glNamedFramebufferTexture(half_fbo_.id(), GL_DEPTH_ATTACHMENT, half_depth_.id(), 0);
  const GLenum half_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(half_fbo_.id(), 2, half_buffers);
  visibility_fbo_ = GlFramebuffer::create();
  glNamedFramebufferTexture(visibility_fbo_.id(), GL_COLOR_ATTACHMENT0, area_visibility_.id(), 0);
  glNamedFramebufferTexture(visibility_fbo_.id(), GL_DEPTH_STENCIL_ATTACHMENT, depth_.id(), 0);
  GI_EXPECTS(half_fbo_.complete() && visibility_fbo_.complete(), "area shadow targets must be complete");
}

std::vector<DrawItem> ForwardRenderer::draw_items(const Registry& registry,
                                                  std::vector<std::pair<Entity, const char*>>& skipped) const {
  std::vector<DrawItem> items;
  registry.view<MeshRenderer, WorldTransform>().each([&](Entity e, const MeshRenderer& mr, const WorldTransform& wt) {
    GI_EXPECTS(mr.mesh < scene_.meshes().size(), "MeshRenderer::mesh must index the renderer's SceneAsset meshes");
    if (const char* why = unusable_world_matrix(wt.matrix)) {
      skipped.emplace_back(e, why);
      return;
    }
    DrawItem item;
    item.entity = e;
    item.mesh = &scene_.meshes()[mr.mesh];
    if (const auto atlas = atlas_overrides_.find(e);
        atlas != atlas_overrides_.end() && atlas->second.source_mesh == mr.mesh)
      item.mesh = &scene_.meshes()[atlas->second.gpu_mesh];
    item.model = wt.matrix;
    item.material_override = mr.material_override;
    item.cast_shadows = mr.cast_shadows;
    item.is_static = registry.has<StaticTag>(e);
    item.bounds = render::item_bounds(*item.mesh, item.model);
    items.push_back(item);
  });
  return items;
}

void ForwardRenderer::sync_atlas_meshes() {
  const std::span<const AtlasMesh> atlas = provider_ ? provider_->atlas_meshes() : std::span<const AtlasMesh>{};
  if (atlas.data() == atlas_drawn_.data() && atlas.size() == atlas_drawn_.size()) return;
  atlas_drawn_ = atlas;
  atlas_overrides_.clear();
  if (Status s = scene_.set_atlas_meshes(atlas); !s) {
    // The provider's geometry is malformed: the static meshes draw the scene's (without TEXCOORD_1).
    log_message(LogLevel::Error, "renderer: atlas meshes not drawn: " + s.error().to_string());
    return;
  }
  for (std::size_t k = 0; k < atlas.size(); ++k)
    atlas_overrides_[atlas[k].entity] = {atlas[k].source_mesh, scene_.scene_mesh_count() + k};
}

// One warning per entity when it starts being skipped; forgotten when it is usable again.
void ForwardRenderer::report_skipped(const Registry& registry,
                                     const std::vector<std::pair<Entity, const char*>>& skipped) {
  skipped_entities_ = static_cast<int>(skipped.size());
  std::set<std::uint32_t> now;
  for (const auto& [e, why] : skipped) {
    now.insert(e.id());
    if (warned_.contains(e.id()) || !settings_.warn) continue;
    const Name* name = registry.try_get<Name>(e);
    settings_.warn("renderer: " + std::string(registry.has<Light>(e) ? "light" : "mesh") + " '" +
                   (name ? name->value : "entity " + std::to_string(e.id())) + "' skipped: " + why);
  }
  warned_ = std::move(now);
}

// Long because it is the frame's passes in order (shadow maps, area lights, light groups,
// indirect light, forward, exposure, tonemap), each timed by the one GpuTimer as it ends.
void ForwardRenderer::render(const Registry& registry, Entity camera, double dt_s) {
  GI_EXPECTS(std::isfinite(dt_s) && dt_s >= 0.0, "render()'s time step must be finite and not negative");
  GI_EXPECTS(registry.valid(camera) && registry.has<Camera>(camera) && registry.has<WorldTransform>(camera),
             "render() needs a camera entity with Camera and WorldTransform");
  ensure_targets();
  timings_.clear();
  GpuTimer timer;

  sync_atlas_meshes();
  std::vector<std::pair<Entity, const char*>> skipped;
  const std::vector<DrawItem> items = draw_items(registry, skipped);
  render::ShadowCapacity capacity;
  capacity.map_size = std::max(16, settings_.shadow_map_size);
  capacity.cube_size = std::max(16, settings_.shadow_map_size / 2);
  capacity.sun_size = std::max(16, settings_.sun_shadow_map_size);
  const render::LightList lights = render::collect_lights(registry, render::scene_bounds(items), capacity, &skipped);
  report_skipped(registry, skipped);
  shadow_maps_.reserve(capacity.map_size, lights.layers_2d, capacity.sun_size, lights.sun_layers, capacity.cube_size,
                       lights.cubes);
  const CameraView view = camera_view(registry, camera);
  // The alpha-tested shadow program only for scenes with MASK or BLEND materials (made on first use).
  const LocatedProgram<DepthUniforms>* shadow_cut_out =
      scene_.has_cut_out() ? &alpha_test_program("shadow.frag.glsl") : nullptr;
  shadow_maps_rendered_ =
      shadow_maps_.render(lights.shadow_views, items, scene_, shadow_, shadow_cut_out, view.view_proj);
  timings_.push_back({"shadow maps (" + std::to_string(lights.shadow_views.size()) + " views)", timer.lap_ms()});

  // Half-resolution area shadows: every area light of the frame (each its visibility channel,
  // GpuLight::shadow_params.z), when they are soft-shadowed, at most 4 and one has a map.
  area_lights_.clear();
  if (settings_.area_shadow_res == AreaShadowRes::Half && settings_.area_soft_shadows && !settings_.flat_shading) {
    for (const render::GpuLight& g : lights.lights)
      if (static_cast<int>(g.position_type.w) == static_cast<int>(render::GpuLightType::Area))
        area_lights_.push_back(g);
    const bool any_map = std::any_of(area_lights_.begin(), area_lights_.end(),
                                     [](const render::GpuLight& g) { return g.cone.z >= 0.0f; });
    if (area_lights_.size() > 4 || !any_map) area_lights_.clear();
  }
  std::vector<LightGroup> groups = light_groups(registry, items, lights);
  light_groups_ = static_cast<int>(groups.size());
  {  // Every group's lights, one after the other (each at an SSBO offset alignment).
    GLint align = 16;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
    const std::size_t a = static_cast<std::size_t>(std::max(align, 1));
    std::vector<std::uint8_t> bytes;
    for (LightGroup& g : groups) {
      const std::size_t at = (bytes.size() + a - 1) / a * a;
      g.offset = static_cast<GLintptr>(at);
      const std::size_t n = std::max<std::size_t>(1, g.lights.size()) * sizeof(render::GpuLight);
      bytes.resize(at + n, 0);
      if (!g.lights.empty())
        std::memcpy(bytes.data() + at, g.lights.data(), g.lights.size() * sizeof(render::GpuLight));
    }
    glNamedBufferData(lights_buffer_.id(), static_cast<GLsizeiptr>(bytes.size()), bytes.data(), GL_STREAM_DRAW);
  }
  // The provider's per-frame work (its GPU passes and their CPU side) is its own pass, so
  // the summary and the overlay show what the GI costs apart from drawing with it.
  const IndirectLightFrame* indirect = nullptr;
  if (provider_) {
    indirect = &provider_->frame();
    timings_.push_back({std::string("indirect light update (") + provider_->label() + ")", timer.lap_ms()});
  }
  forward_pass(view, items, groups, indirect);
  timings_.push_back({provider_ ? std::string("forward + indirect (") + provider_->label() + ")"
                                : std::string("forward + constant ambient (stand-in)"),
                      timer.lap_ms()});

  // Automatic exposure: metered and adapted on the GPU, read by the tonemap (docs/exposure.md).
  exposure_metered_ = settings_.exposure_mode == ExposureMode::Automatic;
  if (exposure_metered_) {
    exposure_meter_.run(hdr_.id(), width_, height_, dt_s, exposure_snap_, settings_.auto_exposure);
    exposure_snap_ = false;
    timings_.push_back({"auto exposure (histogram, adapt)", timer.lap_ms()});
  } else {
    applied_exposure_ = fixed_exposure();
    exposure_snap_ = true;  // switching to automatic starts from the metered target
  }

  tonemap_pass();
  timings_.push_back({"tonemap (exposure, ACES fitted, sRGB)", timer.lap_ms()});
}

ForwardRenderer::CameraView ForwardRenderer::camera_view(const Registry& registry, Entity camera) {
  const Camera& cam = registry.get<Camera>(camera);
  const glm::mat4& camera_now = registry.get<WorldTransform>(camera).matrix;
  if (unusable_world_matrix(camera_now) == nullptr) last_camera_world_ = camera_now;
  const glm::mat4& camera_world = last_camera_world_;
  const float aspect = cam.aspect > 0.0f ? cam.aspect : static_cast<float>(width_) / static_cast<float>(height_);
  return {glm::perspective(cam.yfov_rad, aspect, cam.znear_m, cam.zfar_m) * glm::inverse(camera_world),
          glm::vec3(camera_world[3])};
}

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
  glUniform1i(u.probe_count, in.probes ? in.indirect->reflection_probe_count : 0);
  glUniform1i(u.probe_levels, in.probes ? in.indirect->reflection_probe_levels : 0);
  glUniform1i(u.probe_has_distances, in.probes && in.indirect->reflection_probe_distances ? 1 : 0);
  glUniform1f(u.probe_max_roughness, in.probes ? in.indirect->reflection_probe_max_roughness : 0.0f);
  glUniform1i(u.probe_lobe_samples, in.probes ? in.indirect->reflection_probe_lobe_samples : 0);
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
void ForwardRenderer::shade_group(const ForwardInputs& in, const LightGroup& group,
                                  const std::vector<const DrawItem*>& order, bool blend) {
  if (in.reach && !blend) glStencilFunc(GL_EQUAL, group.mask, area_lights_.empty() ? 0xFF : 0xFF & ~kAreaFallbackBit);
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kLightsBinding, lights_buffer_.id(), group.offset,
                    static_cast<GLsizeiptr>(std::max<std::size_t>(1, group.lights.size()) * sizeof(render::GpuLight)));
  const LightCounts counts{group.count_by_type[0],
                           group.count_by_type[1],
                           group.count_by_type[2],
                           group.count_by_type[3],
                           std::clamp(settings_.area_specular_samples_per_side, 1, 4),
                           settings_.area_soft_shadows ? 1 : 0,
                           in.has_sky ? 1 : 0,
                           area_lights_.empty() ? 0 : 1,
                           settings_.flat_shading ? 1 : 0};
  // Rough dielectrics draw with the one-specular-point variant of area lights (rough_dielectric),
  // the other materials with RenderSettings::area_specular_samples_per_side: two passes over the
  // items, each with its program, when that makes a difference.
  LightCounts rough_counts = counts;
  rough_counts[4] = 1;
  // (Not for BLEND primitives: two passes would break their back-to-front order.)
  const bool split_rough = !blend && counts[3] > 0 && counts[4] > 1 && settings_.area_specular_one_point_on_rough;
  for (int pass = 0; pass < (split_rough ? 2 : 1); ++pass) {
    const LocatedProgram<ForwardUniforms>& program = forward_program(pass == 0 ? counts : rough_counts);
    const ForwardUniforms& u = program.uniforms;
    program.use();
    set_forward_frame_uniforms(u, in, blend);
    const auto in_pass = [&](const DrawItem& item, const render::GpuPrimitive& p) {
      const render::GpuMaterial& m = scene_.material(item.material_override >= 0 ? item.material_override : p.material);
      if ((m.alpha_mode == AlphaMode::Blend) != blend) return false;
      if (!split_rough) return true;
      return rough_dielectric(m, scene_.white_texture()) == (pass == 1);
    };
    for (const DrawItem* drawn : order) {
      const DrawItem& item = *drawn;
      const render::SceneBounds& gb = group.bounds;
      if (!gb.empty &&
          (glm::any(glm::lessThan(item.bounds.max, gb.min)) || glm::any(glm::greaterThan(item.bounds.min, gb.max))))
        continue;  // none of this group's pixels can be on the item
      if (std::none_of(item.mesh->primitives.begin(), item.mesh->primitives.end(),
                       [&](const render::GpuPrimitive& p) { return in_pass(item, p); }))
        continue;
      set_item_indirect(u, item, in);
      glUniformMatrix4fv(u.model, 1, GL_FALSE, glm::value_ptr(item.model));
      const glm::mat4 normal_matrix(glm::transpose(glm::inverse(glm::mat3(item.model))));
      glUniformMatrix4fv(u.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
      for (const render::GpuPrimitive& p : item.mesh->primitives) {
        if (!in_pass(item, p)) continue;
        draw_shaded_primitive(u, scene_.material(item.material_override >= 0 ? item.material_override : p.material), p);
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

void ForwardRenderer::tonemap_pass() {
  glBindFramebuffer(GL_FRAMEBUFFER, ldr_fbo_.id());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  tonemap_.use();
  glUniform1f(tonemap_.uniforms.exposure, exposure_metered_ ? 1.0f : applied_exposure_);
  glUniform1i(tonemap_.uniforms.metered, exposure_metered_ ? 1 : 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kExposureStateBinding, exposure_meter_.state_buffer());
  glBindTextureUnit(0, hdr_.id());
  glBindVertexArray(empty_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

float ForwardRenderer::fixed_exposure() const {
  return settings_.exposure_mode == ExposureMode::FixedEv100 ? exposure_of_ev100(settings_.ev100) : settings_.exposure;
}

ExposureReading ForwardRenderer::read_exposure() const {
  ExposureReading r;
  if (!exposure_metered_) {
    r.exposure = applied_exposure_;
    r.ev100 = r.exposure > 0.0f ? ev100_of_exposure(r.exposure) : 0.0f;
    r.target_ev100 = r.ev100;
    return r;
  }
  const GpuExposureState s = exposure_meter_.read();
  r.exposure = s.exposure;
  r.ev100 = s.ev100;
  r.target_ev100 = s.target_ev100;
  r.mean_log2_luminance = s.mean_log2_luminance;
  r.metered_pixels = s.metered_pixels;
  r.metered = true;
  return r;
}

ImageRgba8 ForwardRenderer::read_ldr() const {
  ImageRgba8 image;
  image.width = width_;
  image.height = height_;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(ldr_.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(raw.size()), raw.data());
  image.pixels.resize(raw.size());
  const std::size_t row = static_cast<std::size_t>(width_) * 4;
  for (int y = 0; y < height_; ++y)  // GL rows run bottom to top
    std::copy_n(raw.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(height_ - 1 - y)), row,
                image.pixels.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y)));
  return image;
}

ImageRgbaF ForwardRenderer::read_hdr() const {
  ImageRgbaF image;
  image.width = width_;
  image.height = height_;
  std::vector<float> raw(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(hdr_.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(raw.size() * sizeof(float)), raw.data());
  image.pixels.resize(raw.size());
  const std::size_t row = static_cast<std::size_t>(width_) * 4;
  for (int y = 0; y < height_; ++y)
    std::copy_n(raw.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(height_ - 1 - y)), row,
                image.pixels.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y)));
  return image;
}

}  // namespace engine::render

namespace engine {

Result<std::unique_ptr<Renderer>> Renderer::create(const SceneAsset& assets, const RenderSettings& settings) {
  using namespace render;
  GI_EXPECTS(settings.width > 0 && settings.height > 0, "RenderSettings width and height must be positive");
  if (glGetString(GL_VERSION) == nullptr)
    return Error{assets.source, "renderer", "no current OpenGL context (create an engine::GpuContext first)"};
  auto forward = build_forward(LightCounts{0, 0, 0, 0, 3, 1, 1, 0});
  if (!forward) return forward.error();
  auto depth = build_depth("depth_only.frag.glsl");
  if (!depth) return depth.error();
  auto depth_reach = build_depth("depth_reach.frag.glsl");
  if (!depth_reach) return depth_reach.error();
  auto shadow = build_depth("shadow.frag.glsl");
  if (!shadow) return shadow.error();
  ShaderProgramBuilder tonemap_builder(engine_shader_files());
  auto tonemap = link_program<TonemapUniforms>(
      define_exposure_constants(tonemap_builder),
      {{ShaderStage::Vertex, "fullscreen.vert.glsl"}, {ShaderStage::Fragment, "tonemap.frag.glsl"}});
  if (!tonemap) return tonemap.error();
  auto exposure_meter = ExposureMeter::create();
  if (!exposure_meter) return exposure_meter.error();
  auto scene = GpuScene::upload(assets);
  if (!scene) return scene.error();
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  RenderSettings with_sky = settings;
  with_sky.sky_radiance = assets.environment.sky_radiance;
  with_sky.sky_gradient = assets.environment.sky_gradient;
  return std::unique_ptr<Renderer>(std::make_unique<ForwardRenderer>(
      std::move(scene.value()), std::move(forward.value()), std::move(depth.value()), std::move(depth_reach.value()),
      std::move(shadow.value()), std::move(tonemap.value()), std::move(exposure_meter.value()), with_sky));
}

}  // namespace engine
