// engine::Renderer: shadow maps, a forward linear-HDR pass (RGBA16F + depth), then
// exposure, ACES-fitted tonemap and sRGB encoding into an RGBA8 target.
#include <engine/renderer.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <utility>
#include <string>

#include <GL/glcorearb.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <engine/components.h>
#include <engine/light_reach.h>
#include <engine/runtime_limits.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gltf_brdf_texture.h>
#include <engine/gpu/gpu_timer.h>
#include <engine/gpu/shader_program.h>

#include "render/frame_data.h"
#include "render/gpu_scene.h"
#include "render/light_list.h"
#include "render/shadow_maps.h"

namespace engine {

namespace {

using render::DrawItem;
using render::GpuScene;

// Texture units and SSBO bindings shared with forward.frag.glsl / shadow_common.glsl.
enum TextureUnit : GLuint {
  kBaseColorUnit = 0,
  kMetallicRoughnessUnit = 1,
  kEmissiveUnit = 2,
  kIrradianceAtlasUnit = 3,
  kShadowMapsUnit = 4,
  kPointShadowMapsUnit = 5,
  kGlossyUnit = 6,
  kDirectionalIndexUnit = 7,
  kShadowDepthUnit = 12,  // the 2-D shadow maps again, raw depth (shadow_common.glsl's sun disc)
  kAreaVisibilityUnit = 13,  // area_shadow.frag.glsl: half-resolution visibility; forward: full-resolution
  kAreaPlaneUnit = 14,       // area_shadow.frag.glsl: half-resolution tangent planes
};
// The stencil's top bit: pixels whose area-light visibility the half-resolution pass could
// not lend (area_shadow.frag.glsl); the light-reach masks use the 7 bits below it then.
constexpr GLuint kAreaFallbackBit = 0x80;
constexpr GLuint kLightsBinding = 0;
constexpr GLuint kVertexIrradianceBinding = 1;
constexpr GLuint kDirectionalRadianceBinding = 2;  // directional_radiance.glsl
constexpr GLuint kDirectionalDirectionBinding = 3;
constexpr GLuint kLobeCoefficientsBinding = 6;  // forward.vert.glsl: IndirectLightFrame::vertex_radiance_lobes
constexpr GLuint kLobeTableBinding = 7;
constexpr GLuint kReachUnit = 0;  // depth_reach.frag.glsl (the pre-pass binds no material texture)
constexpr float kReachVoxelM = 0.5f;  // light reach grid spacing (engine/light_reach.h)

// Nearest, clamped, no depth comparison: the 2-D shadow maps read as depths (the blocker
// search of a directional light with a disc, shadow_common.glsl).
GlSampler raw_depth_sampler() {
  GlSampler s = GlSampler::create();
  glSamplerParameteri(s.id(), GL_TEXTURE_COMPARE_MODE, GL_NONE);
  glSamplerParameteri(s.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glSamplerParameteri(s.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return s;
}

// A 1x1 R32I texture holding -1 ("no element"): what the directional index sampler reads
// when the provider has no directional radiance.
GlTexture no_directional_index() {
  GlTexture t = GlTexture::create_2d(GL_R32I, 1, 1);
  const GLint none = -1;
  glTextureSubImage2D(t.id(), 0, 0, 0, 1, 1, GL_RED_INTEGER, GL_INT, &none);
  glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return t;
}

enum IndirectMode : int { kIndirectNone = 0, kIndirectAmbient = 1, kIndirectAtlas = 2, kIndirectVertex = 3 };

Result<ShaderProgram> build(const char* vertex, const char* fragment) {
  return ShaderProgramBuilder(engine_shader_files())
      .stage(ShaderStage::Vertex, vertex)
      .stage(ShaderStage::Fragment, fragment)
      .build();
}

// Point, spot, directional and area light counts, then area specular samples per side,
// whether area lights are soft-shadowed (RenderSettings::area_soft_shadows), whether the
// scene has a sky term (0: its radiance and gradient are zero, the shader leaves it out) and
// whether area lights' visibility comes from the half-resolution pass (area_shadow_res).
using LightCounts = std::array<int, 8>;

// The forward program for one combination of light counts (see forward.frag.glsl).
Result<ShaderProgram> build_forward(const LightCounts& n) {
  return ShaderProgramBuilder(engine_shader_files())
      .stage(ShaderStage::Vertex, "forward.vert.glsl")
      .stage(ShaderStage::Fragment, "forward.frag.glsl")
      .define("POINT_LIGHTS " + std::to_string(n[0]))
      .define("SPOT_LIGHTS " + std::to_string(n[1]))
      .define("DIRECTIONAL_LIGHTS " + std::to_string(n[2]))
      .define("AREA_LIGHTS " + std::to_string(n[3]))
      .define("AREA_SPECULAR_SIDE " + std::to_string(n[4]))
      .define("AREA_SOFT_SHADOWS " + std::to_string(n[5]))
      .define("SKY_TERM " + std::to_string(n[6]))
      .define("AREA_SHADOW_HALF " + std::to_string(n[7]))
      .build();
}

// One pass of the half-resolution area shadows (area_shadow.frag.glsl) for `area_lights` lights.
Result<ShaderProgram> build_area_shadow(int pass, int area_lights) {
  return ShaderProgramBuilder(engine_shader_files())
      .stage(ShaderStage::Vertex, "forward.vert.glsl")
      .stage(ShaderStage::Fragment, "area_shadow.frag.glsl")
      .define("AREA_SHADOW_PASS " + std::to_string(pass))
      .define("AREA_LIGHTS " + std::to_string(area_lights))
      .build();
}

// The lights one set of pixels is shaded with: those of one light-reach mask (the stencil
// value the pre-pass wrote), as a range of the lights buffer.
struct LightGroup {
  int mask = -1;  ///< stencil value; -1: no stencil test (no reach grid)
  std::vector<render::GpuLight> lights;  ///< sorted by type, like LightList::lights
  std::array<int, 4> count_by_type{};
  render::SceneBounds bounds;  ///< where the mask's voxels are; empty: everywhere
  GLintptr offset = 0;         ///< into the lights buffer (bytes)
};

// The static shadow casters and static lights a reach grid was built from, and the grid.
struct ReachState {
  std::vector<float> light_key;  // the cullable static lights' entity ids and geometry
  std::vector<float> moving_key;  // the cullable moving lights' entity ids and positions
  std::vector<ReachOccluder> occluders;  // the static casters of the last static build
  render::SceneBounds statics;           // the grid's extent: every static item
  LightReachGrid static_grid;            // the static lights' bits
  std::map<std::uint32_t, glm::mat4> static_models;  // static occluders at the build
  std::set<std::uint32_t> moved;  // static entities seen moving: never occluders again
  LightReachGrid grid;
  std::vector<int> mask_bounds_index;  // per mask value: index into bounds, -1 none
  std::vector<render::SceneBounds> bounds;
  GlTexture texture;
  int builds = 0;
};

class ForwardRenderer final : public Renderer {
 public:
  ForwardRenderer(GpuScene scene, ShaderProgram forward, ShaderProgram depth, ShaderProgram depth_reach,
                  ShaderProgram shadow, ShaderProgram tonemap, const RenderSettings& settings)
      : settings_(settings),
        scene_(std::move(scene)),
        depth_only_(std::move(depth)),
        depth_reach_(std::move(depth_reach)),

        shadow_(std::move(shadow)),
        tonemap_(std::move(tonemap)),
        lights_buffer_(GlBuffer::create()),
        empty_vao_(GlVertexArray::create()),
        albedo_table_(upload_gltf_albedo_table()),
        no_directional_index_(no_directional_index()),
        shadow_depth_sampler_(raw_depth_sampler()) {
    forward_variants_.emplace(LightCounts{0, 0, 0, 0, 3, 1, 1, 0}, std::move(forward));
    ensure_targets();
  }

  void render(const Registry& registry, Entity camera) override;
  ImageRgba8 read_ldr() const override;
  ImageRgbaF read_hdr() const override;
  void present(int window_width, int window_height) const override {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitNamedFramebuffer(ldr_fbo_.id(), 0, 0, 0, width_, height_, 0, 0, window_width, window_height,
                           GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }
  void set_indirect_light(IndirectLightProvider* provider) override { provider_ = provider; }
  RenderSettings& settings() override { return settings_; }
  const std::vector<PassTiming>& last_timings() const override { return timings_; }
  int last_shadow_maps_rendered() const override { return shadow_maps_rendered_; }
  int last_skipped_entities() const override { return skipped_entities_; }
  int last_light_groups() const override { return light_groups_; }

 private:
  void ensure_targets();
  std::vector<DrawItem> draw_items(const Registry& registry, std::vector<std::pair<Entity, const char*>>& skipped) const;
  void report_skipped(const Registry& registry, const std::vector<std::pair<Entity, const char*>>& skipped);
  void forward_pass(const Registry& registry, Entity camera, const std::vector<DrawItem>& items,
                    const std::vector<LightGroup>& groups);
  const ShaderProgram& forward_program(const LightCounts& counts);
  const ShaderProgram& area_shadow_program(int pass, int area_lights);
  void area_shadow_passes(const glm::mat4& view_proj, const glm::vec3& camera_position, const std::vector<DrawItem>& items);
  void draw_geometry(const std::vector<DrawItem>& items, bool double_sided_uniform);
  void depth_prepass(const glm::mat4& view_proj, const std::vector<DrawItem>& items, bool reach);
  std::vector<LightGroup> light_groups(const Registry& registry, const std::vector<DrawItem>& items,
                                       const render::LightList& lights);
  void update_reach(const std::vector<DrawItem>& items, const render::LightList& lights, const std::vector<int>& cullable,
                    int n_static);
  void tonemap_pass();

  RenderSettings settings_;
  GpuScene scene_;
  std::map<LightCounts, ShaderProgram> forward_variants_;
  std::map<std::pair<int, int>, ShaderProgram> area_shadow_programs_;  // (pass, area lights)
  // Half-resolution area shadows (RenderSettings::area_shadow_res): this frame's area lights
  // (empty: full-resolution lookups), their buffer, the half-resolution targets and the
  // full-resolution visibility the forward pass reads.
  std::vector<render::GpuLight> area_lights_;
  GlBuffer area_lights_buffer_ = GlBuffer::create();
  GlTexture half_depth_;
  GlTexture half_visibility_;
  GlTexture half_plane_;
  GlTexture area_visibility_;
  GlFramebuffer half_fbo_;
  GlFramebuffer visibility_fbo_;
  ShaderProgram depth_only_;
  ShaderProgram depth_reach_;
  ReachState reach_;
  ShaderProgram shadow_;
  ShaderProgram tonemap_;
  render::ShadowMaps shadow_maps_;
  int shadow_maps_rendered_ = 0;
  int skipped_entities_ = 0;
  int light_groups_ = 1;
  std::set<std::uint32_t> warned_;  // entity ids skipped and reported, while they stay unusable
  glm::mat4 last_camera_world_{1.0f};
  GlBuffer lights_buffer_;
  GlVertexArray empty_vao_;
  GlTexture albedo_table_;  // gltf_brdf.glsl's directional albedo table
  GlTexture no_directional_index_;
  GlSampler shadow_depth_sampler_;  // no depth compare: the sun disc's blocker search reads depths
  GlTexture hdr_;
  GlTexture depth_;
  GlTexture ldr_;
  GlFramebuffer hdr_fbo_;
  GlFramebuffer ldr_fbo_;
  int width_ = 0;
  int height_ = 0;
  IndirectLightProvider* provider_ = nullptr;
  std::vector<PassTiming> timings_;
};

const ShaderProgram& ForwardRenderer::area_shadow_program(int pass, int area_lights) {
  const std::pair<int, int> key(pass, area_lights);
  auto it = area_shadow_programs_.find(key);
  if (it != area_shadow_programs_.end()) return it->second;
  Result<ShaderProgram> p = build_area_shadow(pass, area_lights);
  if (!p) std::fprintf(stderr, "%s\n", p.error().to_string().c_str());
  GI_EXPECTS(p.ok(), "area shadow shader must compile");
  return area_shadow_programs_.emplace(key, std::move(p.value())).first->second;
}

const ShaderProgram& ForwardRenderer::forward_program(const LightCounts& counts) {
  auto it = forward_variants_.find(counts);
  if (it != forward_variants_.end()) return it->second;
  Result<ShaderProgram> p = build_forward(counts);
  // The variant without lights compiled in create(); a failure here is a shader bug.
  if (!p) std::fprintf(stderr, "%s\n", p.error().to_string().c_str());
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
    item.model = wt.matrix;
    item.material_override = mr.material_override;
    item.cast_shadows = mr.cast_shadows;
    item.is_static = registry.has<StaticTag>(e);
    item.bounds = render::item_bounds(*item.mesh, item.model);
    items.push_back(item);
  });
  return items;
}

// One warning per entity when it starts being skipped; forgotten when it is usable again.
void ForwardRenderer::report_skipped(const Registry& registry, const std::vector<std::pair<Entity, const char*>>& skipped) {
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

void ForwardRenderer::render(const Registry& registry, Entity camera) {
  GI_EXPECTS(registry.valid(camera) && registry.has<Camera>(camera) && registry.has<WorldTransform>(camera),
             "render() needs a camera entity with Camera and WorldTransform");
  ensure_targets();
  timings_.clear();
  GpuTimer timer;

  std::vector<std::pair<Entity, const char*>> skipped;
  const std::vector<DrawItem> items = draw_items(registry, skipped);
  render::ShadowCapacity capacity;
  capacity.map_size = std::max(16, settings_.shadow_map_size);
  capacity.cube_size = std::max(16, settings_.shadow_map_size / 2);
  const render::LightList lights = render::collect_lights(registry, render::scene_bounds(items), capacity, &skipped);
  report_skipped(registry, skipped);
  shadow_maps_.reserve(capacity.map_size, lights.layers_2d, capacity.cube_size, lights.cubes);
  shadow_maps_rendered_ = shadow_maps_.render(lights.shadow_views, items, scene_, shadow_);
  timings_.push_back({"shadow maps (" + std::to_string(lights.shadow_views.size()) + " views)", timer.lap_ms()});

  // Half-resolution area shadows: every area light of the frame (each its visibility channel,
  // GpuLight::shadow_params.z), when they are soft-shadowed, at most 4 and one has a map.
  area_lights_.clear();
  if (settings_.area_shadow_res == AreaShadowRes::Half && settings_.area_soft_shadows) {
    for (const render::GpuLight& g : lights.lights)
      if (static_cast<int>(g.position_type.w) == static_cast<int>(render::GpuLightType::Area)) area_lights_.push_back(g);
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
      if (!g.lights.empty()) std::memcpy(bytes.data() + at, g.lights.data(), g.lights.size() * sizeof(render::GpuLight));
    }
    glNamedBufferData(lights_buffer_.id(), static_cast<GLsizeiptr>(bytes.size()), bytes.data(), GL_STREAM_DRAW);
  }
  forward_pass(registry, camera, items, groups);
  timings_.push_back({provider_ ? std::string("forward + indirect (") + provider_->label() + ")"
                                : std::string("forward + constant ambient (stand-in)"),
                      timer.lap_ms()});

  tonemap_pass();
  timings_.push_back({"tonemap (exposure, ACES fitted, sRGB)", timer.lap_ms()});
}

std::vector<LightGroup> ForwardRenderer::light_groups(const Registry& registry, const std::vector<DrawItem>& items,
                                                      const render::LightList& lights) {
  // Culled by reach: static (not Light::moves), shadowed point, spot and area lights (an
  // unshadowed light shines through walls in this renderer; a directional one reaches
  // everything it is not shadowed from), then moving shadowed point lights (their reach is
  // recomputed on every frame they move; a moving spot, the flashlight, lights what the
  // camera sees and stays on). The first LightReachGrid::kMaxLights of them; bit i of a
  // mask is cullable[i].
  std::vector<int> cullable;
  int n_static = 0;
  // With half-resolution area shadows the stencil's top bit flags their fallback pixels.
  const std::size_t max_cullable = LightReachGrid::kMaxLights - (area_lights_.empty() ? 0 : 1);
  if (settings_.light_reach_culling)
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t i = 0; i < lights.lights.size() && cullable.size() < max_cullable; ++i) {
        const render::GpuLight& g = lights.lights[i];
        const Light* l = registry.try_get<Light>(lights.entities[i]);
        const bool shadowed = g.cone.z >= 0.0f || g.cone.w >= 0.0f;
        if (l == nullptr || !shadowed || l->type == LightType::Directional) continue;
        if (pass == 0 ? !l->moves : (l->moves && l->type == LightType::Point)) cullable.push_back(static_cast<int>(i));
      }
      if (pass == 0) n_static = static_cast<int>(cullable.size());
    }
  LightGroup everything;
  everything.lights = lights.lights;
  everything.count_by_type = lights.count_by_type;
  if (cullable.empty()) return {everything};
  update_reach(items, lights, cullable, n_static);
  if (reach_.grid.empty()) return {everything};
  std::vector<LightGroup> groups;
  for (int mask = 0; mask < 256; ++mask) {
    const int bi = reach_.mask_bounds_index[static_cast<std::size_t>(mask)];
    if (bi < 0 && mask != reach_.grid.all) continue;
    LightGroup g;
    g.mask = mask;
    // The all-lights mask also covers everything outside the grid: no bounds.
    if (mask != reach_.grid.all) g.bounds = reach_.bounds[static_cast<std::size_t>(bi)];
    for (std::size_t i = 0; i < lights.lights.size(); ++i) {
      const auto it = std::find(cullable.begin(), cullable.end(), static_cast<int>(i));
      if (it != cullable.end() && (mask & (1 << (it - cullable.begin()))) == 0) continue;
      g.lights.push_back(lights.lights[i]);
      ++g.count_by_type[static_cast<std::size_t>(lights.lights[i].position_type.w)];
    }
    groups.push_back(std::move(g));
  }
  return groups;
}

// Rebuilds the static lights' reach grid when they or the static shadow casters changed
// since the last build. A static item seen at a new transform is never an occluder again
// (a door that swings): the grid stays conservative while it moves, and is not rebuilt for
// it every frame. The moving lights' bits are recomputed whenever one of them moved.
void ForwardRenderer::update_reach(const std::vector<DrawItem>& items, const render::LightList& lights,
                                   const std::vector<int>& cullable, int n_static) {
  std::vector<float> key, moving_key;
  std::vector<ReachLight> static_lights, moving_lights;
  for (std::size_t c = 0; c < cullable.size(); ++c) {
    const std::size_t i = static_cast<std::size_t>(cullable[c]);
    const render::GpuLight& g = lights.lights[i];
    ReachLight r;
    r.position = glm::vec3(g.position_type);
    r.direction = glm::vec3(g.direction_range);
    if (static_cast<int>(g.position_type.w) == static_cast<int>(render::GpuLightType::Area)) {
      r.half_x = glm::vec3(g.area_half_x);
      r.half_y = glm::vec3(g.area_half_y);
    }
    const bool is_static = static_cast<int>(c) < n_static;
    (is_static ? static_lights : moving_lights).push_back(r);
    std::vector<float>& k = is_static ? key : moving_key;
    k.push_back(static_cast<float>(lights.entities[i].id()));
    for (const glm::vec3& v : {r.position, r.direction, r.half_x, r.half_y}) k.insert(k.end(), {v.x, v.y, v.z});
  }
  std::map<std::uint32_t, glm::mat4> models;
  for (const DrawItem& item : items)
    if (item.is_static && item.cast_shadows && !reach_.moved.contains(item.entity.id())) models[item.entity.id()] = item.model;
  const bool built = reach_.builds > 0;
  const bool static_changed = !built || key != reach_.light_key || models != reach_.static_models;
  if (!static_changed && moving_key == reach_.moving_key) return;
  if (static_changed) {
    if (built)
      for (const auto& [id, m] : models) {
        const auto it = reach_.static_models.find(id);
        if (it != reach_.static_models.end() && it->second != m) reach_.moved.insert(id);
      }
    for (std::uint32_t id : reach_.moved) models.erase(id);
    reach_.occluders.clear();
    reach_.statics = render::SceneBounds{};
    render::SceneBounds& statics = reach_.statics;
    for (const DrawItem& item : items) {
      if (!item.is_static) continue;
      statics.min = statics.empty ? item.bounds.min : glm::min(statics.min, item.bounds.min);
      statics.max = statics.empty ? item.bounds.max : glm::max(statics.max, item.bounds.max);
      statics.empty = false;
      if (!models.contains(item.entity.id())) continue;
      ReachOccluder o;
      o.min = item.bounds.min;
      o.max = item.bounds.max;
      const std::vector<glm::vec3>& c = item.mesh->triangle_corners;
      for (std::size_t t = 0; t + 2 < c.size(); t += 3)
        o.triangles.push_back({glm::vec3(item.model * glm::vec4(c[t], 1.0f)),
                               glm::vec3(item.model * glm::vec4(c[t + 1], 1.0f)),
                               glm::vec3(item.model * glm::vec4(c[t + 2], 1.0f))});
      reach_.occluders.push_back(std::move(o));
    }
    reach_.light_key = std::move(key);
    reach_.static_models = std::move(models);
    ++reach_.builds;
    reach_.static_grid = statics.empty ? LightReachGrid{}
                                       : build_light_reach_grid(reach_.occluders, static_lights, statics.min, statics.max,
                                                                kReachVoxelM);
  }
  reach_.moving_key = std::move(moving_key);
  LightReachGrid moving;
  if (!moving_lights.empty() && !reach_.statics.empty)
    moving = build_light_reach_grid(reach_.occluders, moving_lights, reach_.statics.min, reach_.statics.max, kReachVoxelM);
  // Static bits low, moving bits above them (both grids span the same voxels).
  const glm::ivec3 old_dims = reach_.grid.dims;
  reach_.grid = !reach_.static_grid.empty() ? reach_.static_grid : moving;
  if (!reach_.static_grid.empty() && !moving.empty() && moving.dims == reach_.grid.dims)
    for (std::size_t v = 0; v < reach_.grid.masks.size(); ++v)
      reach_.grid.masks[v] = static_cast<std::uint8_t>(reach_.grid.masks[v] | (moving.masks[v] << n_static));
  reach_.grid.all = static_cast<std::uint8_t>((1u << cullable.size()) - 1u);
  reach_.mask_bounds_index.assign(256, -1);
  reach_.bounds.clear();
  if (reach_.grid.empty()) return;
  const LightReachGrid& g = reach_.grid;
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        const std::uint8_t m = g.masks[static_cast<std::size_t>((z * g.dims.y + y) * g.dims.x + x)];
        int& bi = reach_.mask_bounds_index[m];
        if (bi < 0) {
          bi = static_cast<int>(reach_.bounds.size());
          reach_.bounds.emplace_back();
        }
        render::SceneBounds& b = reach_.bounds[static_cast<std::size_t>(bi)];
        const glm::vec3 lo = g.origin + glm::vec3(x, y, z) * g.voxel_m;
        const glm::vec3 hi = lo + glm::vec3(g.voxel_m);
        b.min = b.empty ? lo : glm::min(b.min, lo);
        b.max = b.empty ? hi : glm::max(b.max, hi);
        b.empty = false;
      }
  if (reach_.texture.empty() || old_dims.x != g.dims.x || old_dims.y != g.dims.y || old_dims.z != g.dims.z) {
    reach_.texture = GlTexture::create(GL_TEXTURE_3D);
    glTextureStorage3D(reach_.texture.id(), 1, GL_R8UI, g.dims.x, g.dims.y, g.dims.z);
    glTextureParameteri(reach_.texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(reach_.texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  GLint unpack = 4;
  glGetIntegerv(GL_UNPACK_ALIGNMENT, &unpack);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(reach_.texture.id(), 0, 0, 0, 0, g.dims.x, g.dims.y, g.dims.z, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
                      g.masks.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, unpack);
}

// A dielectric whose roughness is at least kRoughForOnePoint everywhere (no roughness texture):
// its GGX lobe is far wider than the spread of directions to an area light's points, so one
// specular point per rectangle (the centre) gives its radiance within about 1% (1.02% worst
// at roughness 0.9, RendererAreaLight.RoughDielectricsTakeOneSpecularPoint).
constexpr float kRoughForOnePoint = 0.9f;
bool rough_dielectric(const render::GpuMaterial& m, GLuint white_texture) {
  return m.metallic == 0.0f && m.roughness >= kRoughForOnePoint && m.metallic_roughness_texture == white_texture;
}

void ForwardRenderer::forward_pass(const Registry& registry, Entity camera, const std::vector<DrawItem>& items,
                                   const std::vector<LightGroup>& groups) {
  const Camera& cam = registry.get<Camera>(camera);
  const glm::mat4& camera_now = registry.get<WorldTransform>(camera).matrix;
  if (unusable_world_matrix(camera_now) == nullptr) last_camera_world_ = camera_now;
  const glm::mat4& camera_world = last_camera_world_;
  const float aspect = cam.aspect > 0.0f ? cam.aspect : static_cast<float>(width_) / static_cast<float>(height_);
  const glm::mat4 view_proj =
      glm::perspective(cam.yfov_rad, aspect, cam.znear_m, cam.zfar_m) * glm::inverse(camera_world);
  const glm::vec3 camera_position(camera_world[3]);

  const IndirectLightFrame* indirect = provider_ ? &provider_->frame() : nullptr;

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
  const bool reach = !groups.empty() && groups.front().mask >= 0;
  depth_prepass(view_proj, items, reach);
  if (!area_lights_.empty()) {
    area_shadow_passes(view_proj, camera_position, items);
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

  glBindTextureUnit(kShadowMapsUnit, shadow_maps_.maps_2d());
  glBindTextureUnit(kPointShadowMapsUnit, shadow_maps_.cube_maps());
  glBindTextureUnit(kShadowDepthUnit, shadow_maps_.maps_2d());
  glBindSampler(kShadowDepthUnit, shadow_depth_sampler_.id());
  const GLuint atlas = indirect ? indirect->irradiance_atlas_texture : 0;
  const GLuint glossy = indirect ? indirect->glossy_radiance_texture : 0;
  glBindTextureUnit(kIrradianceAtlasUnit, atlas != 0 ? atlas : scene_.white_texture());
  glBindTextureUnit(kGlossyUnit, glossy != 0 ? glossy : scene_.white_texture());
  glBindTextureUnit(kGltfAlbedoTableUnit, albedo_table_.id());
  // Directional radiance of static surfaces (IndirectLightFrame::directional_*), when provided.
  const bool directional = indirect != nullptr && indirect->directional_index_texture != 0 &&
                           indirect->directional_radiance_buffer != 0 && indirect->directional_direction_buffer != 0 &&
                           indirect->directional_bin_count > 0 && indirect->directional_element_count > 0;
  glBindTextureUnit(kDirectionalIndexUnit,
                    directional ? indirect->directional_index_texture : no_directional_index_.id());
  if (directional) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kDirectionalRadianceBinding, indirect->directional_radiance_buffer);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kDirectionalDirectionBinding, indirect->directional_direction_buffer);
  }

  const SkyGradient& sky = settings_.sky_gradient;
  const glm::vec3 zero(0.0f);
  const bool has_sky = glm::any(glm::notEqual(settings_.sky_radiance, zero)) || glm::any(glm::notEqual(sky.horizon, zero)) ||
                       glm::any(glm::notEqual(sky.zenith, zero)) || glm::any(glm::notEqual(sky.ground, zero));
  for (const LightGroup& group : groups) {
    if (reach) glStencilFunc(GL_EQUAL, group.mask, area_lights_.empty() ? 0xFF : 0xFF & ~kAreaFallbackBit);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kLightsBinding, lights_buffer_.id(), group.offset,
                      static_cast<GLsizeiptr>(std::max<std::size_t>(1, group.lights.size()) * sizeof(render::GpuLight)));
    const LightCounts counts{group.count_by_type[0], group.count_by_type[1], group.count_by_type[2],
                             group.count_by_type[3], std::clamp(settings_.area_specular_samples_per_side, 1, 4),
                             settings_.area_soft_shadows ? 1 : 0, has_sky ? 1 : 0, area_lights_.empty() ? 0 : 1};
    // Rough dielectrics draw with the one-specular-point variant of area lights (rough_dielectric),
    // the other materials with RenderSettings::area_specular_samples_per_side: two passes over the
    // items, each with its program, when that makes a difference.
    LightCounts rough_counts = counts;
    rough_counts[4] = 1;
    const bool split_rough = counts[3] > 0 && counts[4] > 1 && settings_.area_specular_one_point_on_rough;
    for (int pass = 0; pass < (split_rough ? 2 : 1); ++pass) {
      const ShaderProgram& program = forward_program(pass == 0 ? counts : rough_counts);
      program.use();
      glUniform1i(29, directional ? indirect->directional_bin_count : 0);
      glUniform1i(30, directional ? indirect->directional_element_count : 0);

      glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(view_proj));
      glUniform3fv(16, 1, glm::value_ptr(camera_position));
      glUniform1f(23, settings_.stand_in_ambient);
      glUniform3fv(31, 1, glm::value_ptr(settings_.sky_radiance));
      {  // The sky's gradient (engine/sky.h): horizon, zenith - horizon, ground - horizon.
        const SkyGradient& g = settings_.sky_gradient;
        const glm::vec3 terms[3] = {g.horizon, g.zenith - g.horizon, g.ground - g.horizon};
        glUniform3fv(61, 3, glm::value_ptr(terms[0]));
      }
      glUniform1f(24, settings_.split == SplitView::DirectLeftFullRight ? 0.5f * static_cast<float>(width_) : -1.0f);
      glUniform1i(25, glossy != 0 ? 1 : 0);

      const auto in_pass = [&](const DrawItem& item, const render::GpuPrimitive& p) {
        if (!split_rough) return true;
        const render::GpuMaterial& m = scene_.material(item.material_override >= 0 ? item.material_override : p.material);
        return rough_dielectric(m, scene_.white_texture()) == (pass == 1);
      };
      for (const DrawItem& item : items) {
        const render::SceneBounds& gb = group.bounds;
        if (!gb.empty && (glm::any(glm::lessThan(item.bounds.max, gb.min)) || glm::any(glm::greaterThan(item.bounds.min, gb.max))))
          continue;  // none of this group's pixels can be on the item
        if (std::none_of(item.mesh->primitives.begin(), item.mesh->primitives.end(),
                         [&](const render::GpuPrimitive& p) { return in_pass(item, p); }))
          continue;
        int mode = kIndirectAmbient;
        GLuint vertex_buffer = 0;
        if (indirect != nullptr) {
          mode = kIndirectNone;
          if (item.is_static && atlas != 0) {
            mode = kIndirectAtlas;
          } else if (!item.is_static) {
            vertex_buffer = indirect->vertex_irradiance_buffer(item.entity);
            if (vertex_buffer != 0) mode = kIndirectVertex;
          }
        }
        {  // The sky's occlusion on a dynamic entity, when the provider measured it (indirect_light.h).
          float axes[6] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
          if (indirect != nullptr && !item.is_static) (void)indirect->sky_visibility(item.entity, axes);
          glUniform3f(64, axes[0], axes[2], axes[4]);
          glUniform3f(65, axes[1], axes[3], axes[5]);
        }
        if (vertex_buffer != 0) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kVertexIrradianceBinding, vertex_buffer);
        // Per-vertex view-dependent indirect light (IndirectLightFrame::vertex_radiance_lobes).
        IndirectLightFrame::VertexRadianceLobes lobes;
        if (vertex_buffer != 0) lobes = indirect->vertex_radiance_lobes(item.entity);
        const bool use_lobes = lobes.terms > 0 && lobes.resolution > 0 && lobes.coefficient_buffer != 0 &&
                               lobes.lobe_buffer != 0 && lobes.first >= 0 && lobes.stride >= 0;
        if (use_lobes) {
          glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLobeCoefficientsBinding, lobes.coefficient_buffer);
          glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLobeTableBinding, lobes.lobe_buffer);
        }
        glUniform1i(40, use_lobes ? lobes.terms : 0);
        glUniform1i(41, lobes.resolution);
        glUniform1i(42, lobes.first);
        glUniform1i(43, lobes.stride);
        glUniform1i(12, item.mesh->first_vertex);
        glUniform1i(13, vertex_buffer != 0 ? 1 : 0);
        glUniform1i(22, mode);
        glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(item.model));
        const glm::mat4 normal_matrix(glm::transpose(glm::inverse(glm::mat3(item.model))));
        glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(normal_matrix));
        for (const render::GpuPrimitive& p : item.mesh->primitives) {
          if (!in_pass(item, p)) continue;
          const render::GpuMaterial& m =
              scene_.material(item.material_override >= 0 ? item.material_override : p.material);
          if (m.double_sided)
            glDisable(GL_CULL_FACE);
          else
            glEnable(GL_CULL_FACE);
          glUniform4fv(18, 1, glm::value_ptr(m.base_color));
          glUniform1f(19, m.metallic);
          glUniform1f(20, m.roughness);
          glUniform3fv(21, 1, glm::value_ptr(m.emissive));
          glUniform1i(26, m.double_sided ? 1 : 0);
          glUniform1f(27, m.specular_factor);
          glUniform3fv(28, 1, glm::value_ptr(m.specular_color_factor));
          glBindTextureUnit(kBaseColorUnit, m.base_color_texture);
          glBindTextureUnit(kMetallicRoughnessUnit, m.metallic_roughness_texture);
          glBindTextureUnit(kEmissiveUnit, m.emissive_texture);
          glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                                   reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                                   p.base_vertex);
        }
      }
    }
  }
  glDisable(GL_STENCIL_TEST);
  glStencilMask(0xFF);
  glDisable(GL_CULL_FACE);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// Every item's primitives with the pre-pass's culling (double-sided materials both faces);
// with `double_sided_uniform`, location 26 says which (area_shadow.frag.glsl flips the normal).
void ForwardRenderer::draw_geometry(const std::vector<DrawItem>& items, bool double_sided_uniform) {
  for (const DrawItem& item : items) {
    glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(item.model));
    if (double_sided_uniform) {
      const glm::mat4 normal_matrix(glm::transpose(glm::inverse(glm::mat3(item.model))));
      glUniformMatrix4fv(4, 1, GL_FALSE, glm::value_ptr(normal_matrix));
      glUniform1i(12, item.mesh->first_vertex);
    }
    for (const render::GpuPrimitive& p : item.mesh->primitives) {
      const bool two = scene_.material(item.material_override >= 0 ? item.material_override : p.material).double_sided;
      if (two)
        glDisable(GL_CULL_FACE);
      else
        glEnable(GL_CULL_FACE);
      if (double_sided_uniform) glUniform1i(26, two ? 1 : 0);
      glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                               reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                               p.base_vertex);
    }
  }
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
  draw_geometry(items, false);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  common_uniforms(area_shadow_program(0, n));
  draw_geometry(items, true);
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
  draw_geometry(items, true);
  // 3. The flagged pixels at full resolution (the stencil rejects the others before shading).
  glStencilMask(0);
  glStencilFunc(GL_EQUAL, static_cast<GLint>(kAreaFallbackBit), kAreaFallbackBit);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  common_uniforms(area_shadow_program(2, n));
  draw_geometry(items, true);
  glDisable(GL_STENCIL_TEST);
  glStencilMask(0xFF);
}

void ForwardRenderer::depth_prepass(const glm::mat4& view_proj, const std::vector<DrawItem>& items, bool reach) {
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  if (reach) {  // the nearest surface's reach mask into the stencil
    depth_reach_.use();
    glEnable(GL_STENCIL_TEST);
    glStencilMask(0xFF);
    glStencilFunc(GL_ALWAYS, 0, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glBindTextureUnit(kReachUnit, reach_.texture.id());
    glUniform3fv(50, 1, glm::value_ptr(reach_.grid.origin));
    glUniform1f(51, 1.0f / reach_.grid.voxel_m);
    glUniform1i(52, reach_.grid.all);
  } else {
    depth_only_.use();
  }
  glUniformMatrix4fv(8, 1, GL_FALSE, glm::value_ptr(view_proj));
  for (const DrawItem& item : items) {
    glUniformMatrix4fv(0, 1, GL_FALSE, glm::value_ptr(item.model));
    for (const render::GpuPrimitive& p : item.mesh->primitives) {
      // Same culling as the shading pass, so both passes see the same surfaces.
      if (scene_.material(item.material_override >= 0 ? item.material_override : p.material).double_sided)
        glDisable(GL_CULL_FACE);
      else
        glEnable(GL_CULL_FACE);
      glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(p.index_count), GL_UNSIGNED_INT,
                               reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p.first_index) * 4u),
                               p.base_vertex);
    }
  }
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_STENCIL_TEST);
}

void ForwardRenderer::tonemap_pass() {
  glBindFramebuffer(GL_FRAMEBUFFER, ldr_fbo_.id());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  tonemap_.use();
  glUniform1f(0, settings_.exposure);
  glBindTextureUnit(0, hdr_.id());
  glBindVertexArray(empty_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
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

}  // namespace

Result<std::unique_ptr<Renderer>> Renderer::create(const SceneAsset& assets, const RenderSettings& settings) {
  GI_EXPECTS(settings.width > 0 && settings.height > 0, "RenderSettings width and height must be positive");
  if (glGetString(GL_VERSION) == nullptr)
    return Error{assets.source, "renderer", "no current OpenGL context (create an engine::GpuContext first)"};
  auto forward = build_forward(LightCounts{0, 0, 0, 0, 3, 1, 1, 0});
  if (!forward) return forward.error();
  auto depth = build("shadow.vert.glsl", "depth_only.frag.glsl");
  if (!depth) return depth.error();
  auto depth_reach = build("shadow.vert.glsl", "depth_reach.frag.glsl");
  if (!depth_reach) return depth_reach.error();
  auto shadow = build("shadow.vert.glsl", "shadow.frag.glsl");
  if (!shadow) return shadow.error();
  auto tonemap = build("fullscreen.vert.glsl", "tonemap.frag.glsl");
  if (!tonemap) return tonemap.error();
  auto scene = GpuScene::upload(assets);
  if (!scene) return scene.error();
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  RenderSettings with_sky = settings;
  with_sky.sky_radiance = assets.environment.sky_radiance;
  with_sky.sky_gradient = assets.environment.sky_gradient;
  return std::unique_ptr<Renderer>(std::make_unique<ForwardRenderer>(std::move(scene.value()), std::move(forward.value()),
                                                                     std::move(depth.value()), std::move(depth_reach.value()),
                                                                     std::move(shadow.value()),
                                                                     std::move(tonemap.value()), with_sky));
}

}  // namespace engine
