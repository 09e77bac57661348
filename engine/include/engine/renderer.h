#pragma once
// The linear-HDR forward renderer: direct light from point, spot, directional and
// rectangular area lights with shadow maps (cube maps for point lights), glTF's BRDF,
// indirect light through engine::IndirectLightProvider, exposure and tonemapping last.
// Shading (engine/shaders/lighting_common.glsl): glTF 2.0's BRDF (engine/gltf_brdf.h and its
// twin engine/shaders/gltf_brdf.glsl: fresnel_mix of Lambert and GGX for dielectrics,
// conductor Fresnel for metals, KHR_materials_specular factors); point/spot
// E = I cos / d^2 with glTF's range window, spot smoothstep(cos outer, cos inner); area
// lights: diffuse is the exact irradiance of the rectangle clipped to the horizon (Lambert's
// polygon formula) times the diffuse lobe's Fresnel weight averaged over n x n stratified
// points, specular those points weighted by cos_l dA / d^2.
// Shadows: cube maps (point), orthographic fitted to the scene bounds (directional),
// perspective (spot; area from the rectangle's centre with 150 degrees, soft over the
// rectangle by PCSS at half resolution by default, and beyond the 150 degrees a cube map from
// the centre for the grazing band).
//   auto ctx = engine::GpuContext::create_headless();              // engine/gpu/context.h
//   auto r = engine::Renderer::create(scene.assets, {.width = 640, .height = 360});
//   r.value()->render(scene.registry, engine::find_camera(scene.registry));
//   engine::save_png("frame.png", r.value()->read_ldr());

#include <memory>
#include <string>
#include <vector>

#include <functional>
#include <string>
#include <engine/entity.h>
#include <engine/exposure.h>
#include <engine/image.h>

#include <engine/indirect_light.h>
#include <engine/registry.h>
#include <engine/result.h>
#include <engine/scene_asset.h>

namespace engine {

/// Where area lights' soft shadows are computed (RenderSettings::area_shadow_res).
enum class AreaShadowRes : std::uint8_t { Full, Half };

/// G toggles the split screen: left half direct light only, right half direct + indirect.
enum class SplitView : std::uint8_t { Off, DirectLeftFullRight };

struct RenderSettings {
  int width = 960;
  int height = 540;
  /// Linear scale applied before tonemapping in ExposureMode::FixedLinear (the default).
  /// LDR = sRGB_encode(ACES_fitted(hdr x exposure)), ACES fitted = Narkowicz 2015:
  /// x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) per channel, clamped to [0, 1].
  float exposure = 1.0f;
  /// How the exposure is chosen (engine/exposure.h, docs/exposure.md): `exposure` as given,
  /// `ev100` through the camera model, or automatic (metered on the GPU from each frame and
  /// adapted over render()'s time step).
  ExposureMode exposure_mode = ExposureMode::FixedLinear;
  /// ExposureMode::FixedEv100: the camera's exposure value at ISO 100; the radiance is scaled
  /// by 683 / (1.2 x 2^ev100) (15: the sunny-16 rule).
  float ev100 = 15.0f;
  /// ExposureMode::Automatic: compensation, clamp, metering percentiles, adaptation rates.
  AutoExposure auto_exposure;
  /// Texels per side of 2-D shadow maps (spot, area); point-light cube faces use half of
  /// it. At most 8 2-D maps and 4 cube maps per frame; further lights are unshadowed.
  int shadow_map_size = 1024;
  /// Texels per side of a directional light's shadow map (the sun's), an array of its own:
  /// it covers the whole level (fitted to the scene bounds as the light sees them), so it
  /// needs more texels than a spot light's cone. 4096: 1 cm texels over a 40 m level,
  /// 64 MB (32-bit depth; twice that while dynamic casters move under a still sun, the
  /// static depth cache). At most 2 directional lights are shadowed. docs/real_level.md
  /// measured it on Dabrovic Sponza (the facades lit at grazing angles need it).
  int sun_shadow_map_size = 4096;
  /// Radiance of the constant ambient stand-in used when no IndirectLightProvider is set,
  /// W/(m^2 sr) per channel; it is labelled "constant ambient (stand-in)" in timings.
  float stand_in_ambient = 0.02f;
  SplitView split = SplitView::Off;
  /// Specular of area lights. 0: materials sharper than roughness 0.3 (no roughness texture)
  /// take the rectangle's integral under a linearly transformed cosine fitted to the GGX lobe
  /// (Heitz et al. 2016; the table is ours, tools/area-ltc-fit), one smooth highlight; the
  /// others (and BLEND primitives) 3 x 3 points, which the fit does not match for wide lobes at
  /// grazing views. 1..4: n x n stratified points per rectangle for every material, whose sum
  /// draws a sharp lobe as n^2 separate highlights. RendererAreaSpecular measures both against
  /// a dense quadrature. The diffuse part is exact whatever the setting.
  int area_specular_samples_per_side = 0;
  /// Dielectrics with roughness >= 0.9 and no roughness texture take one specular point per
  /// rectangle unless area_specular_samples_per_side is 1: their lobe is far wider than
  /// the light's spread of directions (about 1% of their radiance at worst), and
  /// the area light's specular is the costliest part of the forward pass on llvmpipe.
  bool area_specular_one_point_on_rough = true;
  /// Shadows of area lights: true, soft over the rectangle (a blocker search and 16 compare
  /// taps over the rectangle's footprint in its shadow map, PCSS); false, from the
  /// rectangle's centre (a 3x3 grid of bilinear compare taps, cheaper, hard-edged and dark
  /// where the centre is hidden but part of the rectangle is not).
  bool area_soft_shadows = true;
  /// Soft area shadows (area_soft_shadows) per pixel (Full), or at half resolution (Half):
  /// a pass over the scene at half the width and height computes each area light's
  /// visibility (at most 4 area lights; more: Full) and each full-resolution pixel takes the
  /// bilinear mean of the 4 nearest half-resolution texels that lie on its own surface
  /// (tangent plane within 2 cm + 1% of the camera distance, normals within ~25 degrees);
  /// a pixel none of them matches (geometry edges) is computed at full resolution. The light
  /// reach masks then keep 7 lights (the stencil's top bit flags those pixels).
  /// docs/performance-frame.md has the cost (-10 to -21% of the demo level's frame CPU) and
  /// the error (none measurable against the path tracer: docs/replay_quality.md).
  AreaShadowRes area_shadow_res = AreaShadowRes::Half;
  /// Static lights shade only where static geometry lets them reach (engine/light_reach.h):
  /// a voxel grid of light masks built from the static shadow casters when they or the
  /// static lights change, written to the stencil by the depth pre-pass; each pixel is
  /// shaded once with the lights of its mask. Lights that move (Light::moves), directional
  /// and unshadowed lights are shaded everywhere. Off: every light on every pixel.
  bool light_reach_culling = true;
  /// Measurement only, the frame's yardstick: the forward pass writes each surface's base
  /// colour unlit (one texture read), and no area-shadow pass runs; everything else (the
  /// indirect provider's update, the shadow maps, the depth pre-pass, the tonemap) runs as
  /// usual. Its frame time is what any shading costs at least at this size on this device
  /// (tools/perf-report.sh runs it beside the full frame; docs/performance-frame.md).
  bool flat_shading = false;
  /// The scene's sky (SceneAsset::environment.sky_radiance, W/(m^2 sr); Renderer::create
  /// copies it from the assets). Pixels no geometry covers show it (the background). On
  /// surfaces whose baked irradiance holds the sky (IndirectLightFrame::atlas_holds_sky: the
  /// static world under a GI bundle) it comes from the bake, shadowed by the level, and is
  /// not drawn again; elsewhere it is drawn as direct light, an ambient term E = pi x
  /// radiance reflected as uniformly arriving light is, scaled on dynamic meshes by the
  /// provider's sky visibility (unoccluded without one). docs/scene-format.md.
  glm::vec3 sky_radiance{0.0f};
  /// The sky's gradient over the elevation, added to sky_radiance (engine/sky.h;
  /// SceneAsset::environment.sky_gradient, copied by Renderer::create). Its ambient term is
  /// the exact unoccluded irradiance of the surface's normal (engine::sky_irradiance); the
  /// background shows the horizon's radiance.
  SkyGradient sky_gradient;
  /// Told once when a light or mesh entity starts being skipped because its world transform
  /// or light values are not usable (engine/runtime_limits.h: NaN, infinite, absurd); again
  /// only if it recovers and fails anew. Unset: skipped silently (last_skipped_entities()).
  std::function<void(const std::string&)> warn;
};

/// Wall time of one render pass (GPU work measured with glFinish + a steady clock on
/// llvmpipe; see DESIGN.md section 4).
struct PassTiming {
  std::string name;
  double ms = 0.0;
};

class Renderer {
 public:
  /// Uploads meshes, materials and textures of `assets`. Needs a current GL 4.5 context
  /// (engine::GpuContext); destroy the renderer before that context. Malformed meshes or
  /// material image indices return an Error naming the mesh/primitive or material. Normal
  /// textures are not used yet (no tangents); area-light size is Light::area_size_m
  /// (the node's scale is ignored).
  static Result<std::unique_ptr<Renderer>> create(const SceneAsset& assets, const RenderSettings& settings);
  virtual ~Renderer() = default;

  /// Draws the registry's MeshRenderer entities lit by its Light entities, seen from
  /// `camera` (an entity with Camera and WorldTransform), into the offscreen HDR target;
  /// then exposes and tonemaps into the LDR target (and, in a window, the default framebuffer).
  /// `dt_s`: the seconds of game time since the previous render() (>= 0; several fixed
  /// steps when the game steps more often than it draws), which drives automatic exposure's
  /// adaptation. No clock is read, so a replayed or headless run renders the same frames.
  virtual void render(const Registry& registry, Entity camera, double dt_s) = 0;
  /// render(registry, camera, kDefaultFrameDtS): one 60 Hz step since the last frame.
  void render(const Registry& registry, Entity camera) { render(registry, camera, kDefaultFrameDtS); }
  static constexpr double kDefaultFrameDtS = 1.0 / 60.0;

  /// The tonemapped frame (sRGB, rows top to bottom).
  virtual ImageRgba8 read_ldr() const = 0;
  /// The linear HDR frame before exposure and tonemapping.
  virtual ImageRgbaF read_hdr() const = 0;

  /// Blits the LDR result into the currently bound default framebuffer (windowed demo).
  virtual void present(int window_width, int window_height) const = 0;

  /// The provider of indirect light (not owned; nullptr: the constant-ambient stand-in).
  /// How the renderer uses IndirectLightFrame, per MeshRenderer entity:
  /// Indirect irradiance E carries no direction, so it is reflected as uniformly arriving
  /// light is: radiance += E/pi x the BRDF's directional albedo at the view angle, per lobe
  /// (engine::gltf_directional_albedo), where E is
  ///  - for entities with StaticTag: texture(irradiance_atlas_texture, TEXCOORD_1).rgb
  ///    (bilinear, as bound by the provider's sampler state), TEXCOORD_1 of the entity's
  ///    atlas mesh when the provider hands one (IndirectLightProvider::atlas_meshes), else
  ///    of the scene's mesh;
  ///  - for other entities: vertex_irradiance_buffer(entity)[k].irradiance,
  ///    interpolated over the triangle, where k is the vertex's index within the entity's
  ///    mesh with the primitives concatenated in order (primitive p's vertex i has
  ///    k = i + sum of the vertex counts of primitives 0..p-1); the shader reads it as
  ///    gl_VertexID - (scene vertex where the mesh starts). The SSBO is bound at binding 1;
  ///  - for those entities, vertex_radiance_lobes(entity) (if terms > 0) replaces the specular
  ///    lobe's share by the lobes' radiance toward the camera, evaluated per vertex;
  ///  - glossy_radiance_texture (if provided, texelFetch at the pixel) replaces the specular
  ///    lobe's share by its rgb in proportion to its alpha (coverage).
  /// Without a provider every entity gets E = pi x stand_in_ambient (the irradiance of a
  /// uniform sky of that radiance). With SplitView::DirectLeftFullRight
  /// none of this is added to the left half.
  virtual void set_indirect_light(IndirectLightProvider* provider) = 0;
  virtual RenderSettings& settings() = 0;
  /// Timings of the passes of the last render(), in execution order: "shadow maps (N views)",
  /// with an IndirectLightProvider "indirect light update (<provider label>)" (its frame():
  /// the GI's per-frame GPU and CPU work), then "forward + constant ambient (stand-in)" or
  /// "forward + indirect (<provider label>)" (includes the depth pre-pass), with automatic
  /// exposure "auto exposure (histogram, adapt)", then "tonemap (...)".
  virtual const std::vector<PassTiming>& last_timings() const = 0;
  /// Shadow-map views (2-D maps and cube faces) the last render() drew. A view is kept while
  /// neither its light nor a caster that can reach it (not wholly outside its clip volume)
  /// moved: static lights over static casters are drawn once.
  virtual int last_shadow_maps_rendered() const = 0;
  /// Of those, the views of lights that did not move whose dynamic casters did: drawn as a
  /// copy of their static casters' cached depth plus the dynamic casters alone.
  virtual int last_shadow_maps_over_static_depth() const = 0;
  /// Views that changed but were not drawn: the camera cannot see into their volume, so no
  /// pixel looks them up (drawn on the first frame it can).
  virtual int last_shadow_maps_unseen() const = 0;
  /// Light and mesh entities the last render() left out as unusable (see RenderSettings::warn).
  /// A camera whose transform is unusable is replaced by its last usable one.
  virtual int last_skipped_entities() const = 0;
  /// The exposure the last render() applied. Automatic: read back from the GPU (waits for
  /// the frame; for stats, overlays and tests, not needed to draw); fixed modes: no read-back.
  virtual ExposureReading read_exposure() const = 0;
  /// Automatic exposure starts over: the next render() sets the exposure to its frame's
  /// metered target instead of adapting toward it (a cut, a teleport, a new level). The first
  /// automatic frame, and the first after a frame with a fixed mode, do so too.
  virtual void reset_exposure() = 0;
  /// Light sets the last render() shaded pixels with (RenderSettings::light_reach_culling):
  /// one per light-reach mask in the scene's grid, each drawn over the pixels of its mask;
  /// 1 when every pixel got every light.
  virtual int last_light_groups() const { return 1; }
};

}  // namespace engine
