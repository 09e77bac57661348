#pragma once
// engine::render::ForwardRenderer (internal): the engine::Renderer that Renderer::create makes.
// One class in seven files: forward_renderer.cpp (the frame: its targets, draw items, the passes
// in order, Renderer::create), forward_prepass.cpp (what runs before shading: the clear, the
// depth pre-pass and its reach stencil), forward_shading.cpp (the forward pass: program
// variants, inputs, uniforms, drawing), forward_output.cpp (tonemap, exposure, read-back),
// forward_reach.cpp (the light reach grid and the light groups each stencil mask is shaded
// with) and forward_area_shadow.cpp (the area lights' soft shadows at half resolution).
#include <engine/renderer.h>

#include <array>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <GL/glcorearb.h>
#include <glm/glm.hpp>

#include <engine/components.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gltf_brdf_texture.h>
#include <engine/gpu/shader_program.h>
#include <engine/light_reach.h>

#include "render/exposure_meter.h"
#include "render/frame_data.h"
#include "render/gpu_scene.h"
#include "render/light_list.h"
#include "render/program_uniforms.h"
#include "render/shadow_maps.h"

namespace engine::render {

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
  kNormalUnit = 15,          // forward.frag.glsl: the normal texture (render::kMaterialNormalUnit)
  kSunShadowMapsUnit = 10,   // directional lights' own 2-D maps (shadow_common.glsl)
  kSunShadowDepthUnit = 11,  // the same, raw depth (the sun disc's blocker search)
  kShadowDepthUnit = 12,     // the 2-D shadow maps again, raw depth (shadow_common.glsl's sun disc)
  kAreaVisibilityUnit = 13,  // area_shadow.frag.glsl: half-resolution visibility; forward: full-resolution
  kAreaPlaneUnit = 14,       // area_shadow.frag.glsl: half-resolution tangent planes
};
static_assert(int{kBaseColorUnit} == int{render::kMaterialBaseColorUnit} &&
                  int{kMetallicRoughnessUnit} == int{render::kMaterialMetallicRoughnessUnit} &&
                  int{kEmissiveUnit} == int{render::kMaterialEmissiveUnit} &&
                  int{kNormalUnit} == int{render::kMaterialNormalUnit},
              "material texture units agree with gpu_scene.h");
// The stencil's top bit: pixels whose area-light visibility the half-resolution pass could
// not lend (area_shadow.frag.glsl); the light-reach masks use the 7 bits below it then.
constexpr GLuint kAreaFallbackBit = 0x80;
constexpr GLuint kLightsBinding = 0;
constexpr GLuint kVertexIrradianceBinding = 1;
constexpr GLuint kDirectionalRadianceBinding = 2;  // directional_radiance.glsl
constexpr GLuint kDirectionalDirectionBinding = 3;
constexpr GLuint kLobeCoefficientsBinding = 6;  // forward.vert.glsl: IndirectLightFrame::vertex_radiance_lobes
constexpr GLuint kLobeTableBinding = 7;
constexpr GLuint kAreaLtcBinding = 9;          // lighting_common.glsl: the area-light specular's fitted transforms
constexpr GLuint kReflectionProbeBinding = 8;  // reflection_probes.glsl: IndirectLightFrame::reflection_probe_buffer
constexpr GLuint kReflectionProbeUnit = 16;    // reflection_probes.glsl: the probes' cube map array (8: the BRDF table)
constexpr GLuint kReflectionProbeDistanceUnit = 17;  // reflection_probes.glsl: the probes' distance cubes
constexpr GLuint kReachUnit = 9;                     // depth_reach.frag.glsl (unit 0: the alpha test's base colour)
constexpr float kReachVoxelM = 0.5f;                 // light reach grid spacing (engine/light_reach.h)

// Nearest, clamped, no depth comparison: the 2-D shadow maps read as depths (the blocker
// search of a directional light with a disc, shadow_common.glsl).
GlSampler raw_depth_sampler();

// A 1x1 R32I texture holding -1 ("no element"): what the directional index sampler reads
// when the provider has no directional radiance.
GlTexture no_directional_index();

// The area-light specular's fitted transforms (area_ltc_table.h) in a buffer for binding
// kAreaLtcBinding.
GlBuffer upload_area_ltc_table();

// Point, spot, directional and area light counts, then area specular samples per side,
// whether area lights are soft-shadowed (RenderSettings::area_soft_shadows), whether the
// scene has a sky term (0: its radiance and gradient are zero, the shader leaves it out) and
// whether area lights' visibility comes from the half-resolution pass (area_shadow_res).
using LightCounts = std::array<int, 9>;  // ..., [8] FLAT_SHADING (RenderSettings::flat_shading)

// The forward program for one combination of light counts (forward.frag.glsl's defines).
Result<LocatedProgram<ForwardUniforms>> build_forward_program(const LightCounts& counts);

// The lights one set of pixels is shaded with: those of one light-reach mask (the stencil
// value the pre-pass wrote), as a range of the lights buffer.
struct LightGroup {
  int mask = -1;                         ///< stencil value; -1: no stencil test (no reach grid)
  std::vector<render::GpuLight> lights;  ///< sorted by type, like LightList::lights
  std::array<int, 4> count_by_type{};
  render::SceneBounds bounds;  ///< where the mask's voxels are; empty: everywhere
  GLintptr offset = 0;         ///< into the lights buffer (bytes)
};

// The static shadow casters and static lights a reach grid was built from, and the grid.
struct ReachState {
  std::vector<float> light_key;                      // the cullable static lights' entity ids and geometry
  std::vector<float> moving_key;                     // the cullable moving lights' entity ids and positions
  std::vector<ReachOccluder> occluders;              // the static casters of the last static build
  render::SceneBounds statics;                       // the grid's extent: every static item
  LightReachGrid static_grid;                        // the static lights' bits
  std::map<std::uint32_t, glm::mat4> static_models;  // static occluders at the build
  std::set<std::uint32_t> moved;                     // static entities seen moving: never occluders again
  LightReachGrid grid;
  std::vector<int> mask_bounds_index;  // per mask value: index into bounds, -1 none
  std::vector<render::SceneBounds> bounds;
  GlTexture texture;
  int builds = 0;
};

class ForwardRenderer final : public Renderer {
 public:
  ForwardRenderer(GpuScene scene, LocatedProgram<ForwardUniforms> forward, LocatedProgram<DepthUniforms> depth,
                  LocatedProgram<DepthUniforms> depth_reach, LocatedProgram<DepthUniforms> shadow,
                  LocatedProgram<TonemapUniforms> tonemap, ExposureMeter exposure_meter, const RenderSettings& settings)
      : settings_(settings),
        scene_(std::move(scene)),
        depth_only_(std::move(depth)),
        depth_reach_(std::move(depth_reach)),

        shadow_(std::move(shadow)),
        tonemap_(std::move(tonemap)),
        exposure_meter_(std::move(exposure_meter)),
        lights_buffer_(GlBuffer::create()),
        empty_vao_(GlVertexArray::create()),
        albedo_table_(upload_gltf_albedo_table()),
        area_ltc_table_(upload_area_ltc_table()),
        no_directional_index_(no_directional_index()),
        shadow_depth_sampler_(raw_depth_sampler()) {
    forward_variants_.emplace(LightCounts{0, 0, 0, 0, 0, 1, 1, 0, 0}, std::move(forward));
    ensure_targets();
  }

  using Renderer::render;
  void render(const Registry& registry, Entity camera, double dt_s) override;
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
  int last_shadow_maps_over_static_depth() const override { return shadow_maps_.last_cached_views(); }
  int last_shadow_maps_unseen() const override { return shadow_maps_.last_unseen_views(); }
  int last_skipped_entities() const override { return skipped_entities_; }
  int last_light_groups() const override { return light_groups_; }
  ExposureReading read_exposure() const override;
  void reset_exposure() override { exposure_snap_ = true; }

 private:
  void ensure_targets();
  /// Uploads the provider's atlas meshes (IndirectLightProvider::atlas_meshes) when they are
  /// not the ones drawn already, so the renderer may be made before or after the provider.
  void sync_atlas_meshes();
  std::vector<DrawItem> draw_items(const Registry& registry,
                                   std::vector<std::pair<Entity, const char*>>& skipped) const;
  void report_skipped(const Registry& registry, const std::vector<std::pair<Entity, const char*>>& skipped);
  /// The camera's view-projection and position this frame (an unusable world matrix keeps
  /// the last usable one).
  struct CameraView {
    glm::mat4 view_proj{1.0f};
    glm::vec3 position{0.0f};
  };
  CameraView camera_view(const Registry& registry, Entity camera);
  void forward_pass(const CameraView& view, const std::vector<DrawItem>& items, const std::vector<LightGroup>& groups,
                    const IndirectLightFrame* indirect);
  /// What every light group's shading reads: the camera, the provider's frame and what of
  /// it is bound, the reach stencil, whether the scene has a sky term.
  struct ForwardInputs {
    const CameraView* view = nullptr;
    const IndirectLightFrame* indirect = nullptr;
    GLuint atlas = 0;
    GLuint glossy = 0;
    bool directional = false;
    bool probes = false;  ///< IndirectLightFrame::reflection_probe_* provided and bound.
    bool reach = false;
    bool has_sky = false;
  };
  void begin_forward_pass(const CameraView& view, const std::vector<DrawItem>& items, bool reach);
  ForwardInputs bind_forward_inputs(const IndirectLightFrame* indirect);
  void set_forward_frame_uniforms(const ForwardUniforms& u, const ForwardInputs& in, bool blend);
  void set_item_indirect(const ForwardUniforms& u, const DrawItem& item, const ForwardInputs& in);
  void draw_shaded_primitive(const ForwardUniforms& u, const GpuMaterial& m, const GpuPrimitive& p);
  void shade_group(const ForwardInputs& in, const LightGroup& group, const std::vector<const DrawItem*>& order,
                   bool blend);
  void shade_blended(const ForwardInputs& in, const std::vector<DrawItem>& items,
                     const std::vector<LightGroup>& groups);
  const LocatedProgram<ForwardUniforms>& forward_program(const LightCounts& counts);
  const LocatedProgram<AreaShadowUniforms>& area_shadow_program(int pass, int area_lights);
  void area_shadow_passes(const glm::mat4& view_proj, const glm::vec3& camera_position,
                          const std::vector<DrawItem>& items);
  /// `shading` null: the half-resolution depth pass (depth_only_ current); otherwise the area
  /// shadow program `shading` is current.
  void draw_geometry(const std::vector<DrawItem>& items, const LocatedProgram<AreaShadowUniforms>* shading,
                     const glm::mat4& view_proj);
  /// A depth-only fragment stage built with ALPHA_TEST 1 (material_common.glsl), made on first use.
  const LocatedProgram<DepthUniforms>& alpha_test_program(const char* fragment);
  void depth_prepass(const glm::mat4& view_proj, const std::vector<DrawItem>& items, bool reach);
  std::vector<LightGroup> light_groups(const Registry& registry, const std::vector<DrawItem>& items,
                                       const render::LightList& lights);
  void update_reach(const std::vector<DrawItem>& items, const render::LightList& lights,
                    const std::vector<int>& cullable, int n_static);
  void collect_reach_occluders(const std::vector<DrawItem>& items, const std::map<std::uint32_t, glm::mat4>& models);
  void bound_reach_masks();
  void upload_reach_masks(const glm::ivec3& old_dims);
  void tonemap_pass();
  /// The exposure of a fixed mode (FixedLinear, FixedEv100).
  float fixed_exposure() const;

  RenderSettings settings_;
  GpuScene scene_;
  std::map<LightCounts, LocatedProgram<ForwardUniforms>> forward_variants_;
  std::map<std::pair<int, int>, LocatedProgram<AreaShadowUniforms>> area_shadow_programs_;  // (pass, area lights)
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
  LocatedProgram<DepthUniforms> depth_only_;
  LocatedProgram<DepthUniforms> depth_reach_;
  ReachState reach_;
  LocatedProgram<DepthUniforms> shadow_;
  // Fragment stage -> its ALPHA_TEST variant (material_common.glsl): shadow.frag.glsl for MASK
  // and BLEND casters, depth_only / depth_reach.frag.glsl for MASK in the pre-passes.
  std::map<std::string, LocatedProgram<DepthUniforms>> alpha_test_programs_;
  LocatedProgram<TonemapUniforms> tonemap_;
  ExposureMeter exposure_meter_;
  bool exposure_snap_ = true;      ///< The next automatic frame snaps to its target.
  bool exposure_metered_ = false;  ///< The last frame's exposure came from exposure_meter_.
  float applied_exposure_ = 1.0f;  ///< Otherwise, the fixed exposure it was shown with.
  render::ShadowMaps shadow_maps_;
  int shadow_maps_rendered_ = 0;
  int skipped_entities_ = 0;
  int light_groups_ = 1;
  std::set<std::uint32_t> warned_;  // entity ids skipped and reported, while they stay unusable
  glm::mat4 last_camera_world_{1.0f};
  GlBuffer lights_buffer_;
  GlVertexArray empty_vao_;
  GlTexture albedo_table_;   // gltf_brdf.glsl's directional albedo table
  GlBuffer area_ltc_table_;  // lighting_common.glsl's AreaLtc (area_ltc_table.h)
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
  // The atlas meshes in scene_ (the provider's span they came from) and, per static entity,
  // the SceneAsset mesh its atlas mesh replaces and that atlas mesh's index in scene_.
  struct AtlasOverride {
    std::uint32_t source_mesh = 0;
    std::size_t gpu_mesh = 0;
  };
  std::span<const AtlasMesh> atlas_drawn_;
  std::unordered_map<Entity, AtlasOverride> atlas_overrides_;
  std::vector<PassTiming> timings_;
};

}  // namespace engine::render
