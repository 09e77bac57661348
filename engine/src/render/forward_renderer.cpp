// engine::Renderer: shadow maps, a forward linear-HDR pass (RGBA16F + depth), then
// exposure, ACES-fitted tonemap and sRGB encoding into an RGBA8 target. The class is declared
// in render/forward_renderer.h with the map of its files; this one holds the frame (its
// targets, what it draws, its passes in order) and Renderer::create.
#include "render/forward_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <utility>

#include <GL/glcorearb.h>
#include <glm/gtc/matrix_transform.hpp>

#include <engine/components.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gpu_timer.h>
#include <engine/gpu/shader_program.h>
#include <engine/log.h>
#include <engine/runtime_limits.h>

#include "render/area_ltc_table.h"
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

GlBuffer upload_area_ltc_table() {
  GlBuffer b = GlBuffer::create();
  glNamedBufferData(b.id(), static_cast<GLsizeiptr>(sizeof(kAreaLtcTable)), kAreaLtcTable, GL_STATIC_DRAW);
  return b;
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

Result<LocatedProgram<DepthUniforms>> build_depth(const char* fragment) {
  return link_program<DepthUniforms>(ShaderProgramBuilder(engine_shader_files()),
                                     {{ShaderStage::Vertex, "shadow.vert.glsl"}, {ShaderStage::Fragment, fragment}});
}

}  // namespace

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

}  // namespace engine::render

namespace engine {

Result<std::unique_ptr<Renderer>> Renderer::create(const SceneAsset& assets, const RenderSettings& settings) {
  using namespace render;
  GI_EXPECTS(settings.width > 0 && settings.height > 0, "RenderSettings width and height must be positive");
  if (glGetString(GL_VERSION) == nullptr)
    return Error{assets.source, "renderer", "no current OpenGL context (create an engine::GpuContext first)"};
  auto forward = build_forward_program(LightCounts{0, 0, 0, 0, 0, 1, 1, 0});
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
