#pragma once
// The hook through which indirect light enters the engine's shading. The engine declares
// it; the gi library implements it; the game wires the two together. The engine never
// includes gi.
//   class MyGi : public engine::IndirectLightProvider { ... };
//   renderer.set_indirect_light(&my_gi);   // nullptr: the labelled constant-ambient stand-in

#include <cstdint>

#include <engine/entity.h>

namespace engine {

/// What a provider hands the renderer for one frame. GL object names are owned by the
/// provider and stay valid until its next update. 0 means "not provided".
struct IndirectLightFrame {
  /// RGBA16F/RGBA32F 2-D texture of indirect irradiance (W/m^2, linear RGB) sampled with
  /// TEXCOORD_1 of static meshes. Shading reflects it as uniformly arriving light:
  /// E/pi x the BRDF's directional albedo (engine/gltf_brdf.h).
  std::uint32_t irradiance_atlas_texture = 0;
  /// What the irradiance atlas holds besides indirect light, so that nothing is drawn twice
  /// on the static surfaces that read it (docs/scene-format.md, "What is baked and what is
  /// drawn live"):
  ///   atlas_holds_sky            the sky's direct light, shadowed by the static world: the
  ///                              renderer adds no sky term (RenderSettings::sky_radiance) there;
  ///   atlas_holds_static_lights  the direct light of every light that does not move
  ///                              (Light::moves false): those lights add nothing there.
  /// Dynamic meshes keep the sky term (scaled by sky_visibility) and every light.
  bool atlas_holds_sky = false;
  bool atlas_holds_static_lights = false;
  /// Per-vertex indirect irradiance of a dynamic mesh entity: an SSBO of vec4 (W/m^2 in
  /// xyz), one per vertex of the entity's mesh, primitives concatenated in order.
  /// Returns 0 when the entity has none.
  virtual std::uint32_t vertex_irradiance_buffer(Entity) const { return 0; }
  /// Optional view-dependent indirect light of a dynamic mesh entity (a glossy object's
  /// reflection of its surroundings), per vertex j as `terms` coefficients and shared lobes:
  ///   L_spec(w) = sum_{k < terms} c[first + k * stride + j].rgb * h_k(w_local)   (W/(m^2 sr))
  ///   coefficient_buffer  SSBO of vec4 c (rgb used)
  ///   lobe_buffer         SSBO of float, h_k at [k * R * R + v * R + u]: an R x R octahedral map
  ///                       of the upper hemisphere (s = (x + y, x - y) / (|x| + |y| + z), cell
  ///                       (u, v) centred at s = ((u, v) + 0.5) / R * 2 - 1), bilinear between
  ///                       cell centres, clamped at the edges; 0 below the horizon
  ///   w_local             the outgoing (view) direction in the vertex's frame: t, b, n with n the
  ///                       object-space vertex normal and t, b from n as in Duff et al. 2017
  ///                       ("Building an orthonormal basis, revisited"); world directions are
  ///                       turned into object space by the model matrix's rotation
  /// The renderer evaluates L_spec at the vertices toward the camera, interpolates it over the
  /// triangle and uses it in place of the specular lobe's share of vertex_irradiance_buffer's
  /// irradiance (the diffuse lobe keeps that). terms == 0: none.
  struct VertexRadianceLobes {
    std::uint32_t coefficient_buffer = 0;
    std::uint32_t lobe_buffer = 0;
    int first = 0;
    int stride = 0;
    int terms = 0;
    int resolution = 0;
  };
  virtual VertexRadianceLobes vertex_radiance_lobes(Entity) const { return {}; }
  /// Optional glossy (view-dependent) indirect term: an RGBA16F screen-sized texture of
  /// reflected radiance (rgb) and coverage (a): where a = 1 it replaces the specular lobe's
  /// share of the direction-less irradiance above. 0: none.
  std::uint32_t glossy_radiance_texture = 0;
  /// Optional directional radiance of static surfaces at TEXCOORD_1 (a provider's
  /// view-dependent term for glossy static surfaces; gi fills it from directional light
  /// maps). Where a static mesh's texel has an element, the specular lobe of the glTF BRDF is
  /// integrated against the element's bins (engine/directional_radiance.h, the GLSL twin
  /// engine/shaders/directional_radiance.glsl) instead of taking the specular share of the
  /// irradiance atlas, so that share is not counted twice; the diffuse lobe keeps the atlas.
  ///   directional_index_texture      R32I texture of the irradiance atlas's size: the element
  ///                                  index of each texel, -1 where there is none (read nearest)
  ///   directional_radiance_buffer    SSBO, uvec2 per (bin, element), bin-major: packHalf2x16(r, g),
  ///                                  packHalf2x16(b, 0), mean incoming radiance / the bin's scale
  ///   directional_direction_buffer   SSBO, vec4 per bin: unit direction (xyz), the bin's scale (w)
  /// 0 / 0 counts: none.
  std::uint32_t directional_index_texture = 0;
  std::uint32_t directional_radiance_buffer = 0;
  std::uint32_t directional_direction_buffer = 0;
  int directional_bin_count = 0;
  int directional_element_count = 0;

  /// Optional sky occlusion of a dynamic mesh entity (the renderer draws the sky on dynamic
  /// meshes as ambient light, RenderSettings::sky_radiance): the share (0..1) of the sky's unoccluded
  /// irradiance a surface facing +X, -X, +Y, -Y, +Z, -Z gets at the entity, an ambient cube
  /// the provider measured. The renderer scales the entity's sky term by it, blended by the
  /// normal's squared components. False: not provided (unoccluded).
  virtual bool sky_visibility(Entity, float (&/*axes*/)[6]) const { return false; }

  IndirectLightFrame() = default;
  IndirectLightFrame(const IndirectLightFrame&) = default;
  IndirectLightFrame& operator=(const IndirectLightFrame&) = default;
  virtual ~IndirectLightFrame() = default;
};

/// Implemented by the GI system. The renderer calls `frame()` once per rendered frame,
/// after the simulation has run, with the GL context current.
class IndirectLightProvider {
 public:
  virtual ~IndirectLightProvider() = default;
  /// Indirect light for the frame about to be drawn.
  virtual const IndirectLightFrame& frame() = 0;
  /// Short label for the overlay ("light atlas", "PRM", ...).
  virtual const char* label() const = 0;
};

}  // namespace engine
