#pragma once
// The hook through which indirect light enters the engine's shading. The engine declares
// it; the gi library implements it; the game wires the two together. The engine never
// includes gi.
//   class MyGi : public engine::IndirectLightProvider { ... };
//   renderer.set_indirect_light(&my_gi);   // nullptr: the labelled constant-ambient stand-in
//
// The game's scene is never edited for the renderer: a provider whose irradiance atlas is
// read at TEXCOORD_1 hands the static meshes' atlas geometry through atlas_meshes(), and the
// renderer uploads it as its own meshes. So the renderer may be created before or after the
// provider loads; it picks the atlas meshes up on the first frame it sees them.

#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include <engine/entity.h>
#include <engine/scene_asset.h>

namespace engine {

/// A GL texture a provider hands the renderer, owned by the provider. Default: none.
///   frame.irradiance_atlas_texture = engine::TextureHandle{texture.id()};
struct TextureHandle {
  std::uint32_t gl_name = 0;  ///< The GL texture name; 0: none.
  constexpr explicit operator bool() const { return gl_name != 0; }
  friend constexpr bool operator==(TextureHandle, TextureHandle) = default;
};

/// A GL shader storage buffer of `Element`s (std430, tightly packed: Element's size is the
/// array stride), owned by the provider. Default: none.
///   engine::SsboHandle<engine::VertexIrradiance> b{buffer.id()};
template <class Element>
struct SsboHandle {
  using element_type = Element;
  std::uint32_t gl_name = 0;  ///< The GL buffer name; 0: none.
  constexpr explicit operator bool() const { return gl_name != 0; }
  friend constexpr bool operator==(SsboHandle, SsboHandle) = default;
};

// The elements of the SSBOs a provider hands the renderer. The engine's shaders declare the
// same structs (gi's shaders write them); each struct here is one array element, its layout
// asserted against std430 and named after its GLSL twin.

/// One vertex's indirect irradiance (IndirectLightFrame::vertex_irradiance_buffer).
struct VertexIrradiance {
  glm::vec3 irradiance{0.0f};  ///< W/m^2, linear RGB.
  float unused = 0.0f;
};
static_assert(sizeof(VertexIrradiance) == 16 && offsetof(VertexIrradiance, irradiance) == 0,
              "must match struct VertexIrradianceElement in forward.vert.glsl (std430)");

/// One coefficient c of a vertex's view-dependent lobes (VertexRadianceLobes::coefficient_buffer).
struct LobeCoefficient {
  glm::vec3 radiance{0.0f};  ///< W/(m^2 sr), linear RGB.
  float unused = 0.0f;
};
static_assert(sizeof(LobeCoefficient) == 16 && offsetof(LobeCoefficient, radiance) == 0,
              "must match struct LobeCoefficient in forward.vert.glsl (std430)");

/// One cell of a lobe's octahedral map (VertexRadianceLobes::lobe_buffer).
struct LobeCell {
  float value = 0.0f;  ///< h_k at the cell's centre.
};
static_assert(sizeof(LobeCell) == 4 && offsetof(LobeCell, value) == 0,
              "must match struct LobeCell in forward.vert.glsl (std430)");

/// Mean incoming radiance of one (bin, element) of the directional radiance, as half floats
/// over the bin's scale (IndirectLightFrame::directional_radiance_buffer).
struct DirectionalRadiance {
  std::uint32_t red_green = 0;  ///< packHalf2x16(r, g)
  std::uint32_t blue = 0;       ///< packHalf2x16(b, 0)
};
static_assert(sizeof(DirectionalRadiance) == 8 && offsetof(DirectionalRadiance, red_green) == 0 &&
                  offsetof(DirectionalRadiance, blue) == 4,
              "must match struct DirectionalRadianceElement in directional_radiance.glsl (std430)");

/// One direction bin of the directional radiance (IndirectLightFrame::directional_direction_buffer).
struct DirectionalBin {
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  ///< Unit, world space.
  float scale = 1.0f;                     ///< Multiplies the bin's unpacked DirectionalRadiance.
};
static_assert(sizeof(DirectionalBin) == 16 && offsetof(DirectionalBin, direction) == 0 &&
                  offsetof(DirectionalBin, scale) == 12,
              "must match struct DirectionalBin in directional_radiance.glsl (std430)");

/// One reflection probe (IndirectLightFrame::reflection_probe_buffer): where its cube map was
/// captured and the axis-aligned box that stands for its room (parallax correction).
struct ReflectionProbeBox {
  glm::vec4 centre{0.0f};   ///< xyz: the capture point, world space (m); w: unused.
  glm::vec4 box_min{0.0f};  ///< xyz: the box's low corner (m); w: unused.
  glm::vec4 box_max{0.0f};  ///< xyz: the box's high corner (m); w: unused.
};
static_assert(sizeof(ReflectionProbeBox) == 48 && offsetof(ReflectionProbeBox, centre) == 0 &&
                  offsetof(ReflectionProbeBox, box_min) == 16 && offsetof(ReflectionProbeBox, box_max) == 32,
              "must match struct ReflectionProbeBox in reflection_probes.glsl (std430)");

/// What a provider hands the renderer for one frame. The handles' GL objects are owned by the
/// provider and stay valid until its next update; an empty handle means "not provided".
struct IndirectLightFrame {
  /// RGBA16F/RGBA32F 2-D texture of indirect irradiance (W/m^2, linear RGB) sampled with
  /// TEXCOORD_1 of static meshes. Shading reflects it as uniformly arriving light:
  /// E/pi x the BRDF's directional albedo (engine/gltf_brdf.h).
  TextureHandle irradiance_atlas_texture;
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
  /// Per-vertex indirect irradiance of a dynamic mesh entity: one element per vertex of the
  /// entity's mesh, primitives concatenated in order. Empty when the entity has none.
  virtual SsboHandle<VertexIrradiance> vertex_irradiance_buffer(Entity) const { return {}; }
  /// Optional view-dependent indirect light of a dynamic mesh entity (a glossy object's
  /// reflection of its surroundings), per vertex j as `terms` coefficients and shared lobes:
  ///   L_spec(w) = sum_{k < terms} c[first + k * stride + j].rgb * h_k(w_local)   (W/(m^2 sr))
  ///   coefficient_buffer  the coefficients c (LobeCoefficient)
  ///   lobe_buffer         h_k at [k * R * R + v * R + u] (LobeCell): an R x R octahedral map
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
    SsboHandle<LobeCoefficient> coefficient_buffer;
    SsboHandle<LobeCell> lobe_buffer;
    int first = 0;
    int stride = 0;
    int terms = 0;
    int resolution = 0;
  };
  virtual VertexRadianceLobes vertex_radiance_lobes(Entity) const { return {}; }
  /// Optional glossy (view-dependent) indirect term: an RGBA16F screen-sized texture of
  /// reflected radiance (rgb) and coverage (a): where a = 1 it replaces the specular lobe's
  /// share of the direction-less irradiance above. Empty: none.
  TextureHandle glossy_radiance_texture;
  /// Optional directional radiance of static surfaces at TEXCOORD_1 (a provider's
  /// view-dependent term for glossy static surfaces; gi fills it from directional light
  /// maps). Where a static mesh's texel has an element, the specular lobe of the glTF BRDF is
  /// integrated against the element's bins (engine/directional_radiance.h, the GLSL twin
  /// engine/shaders/directional_radiance.glsl) instead of taking the specular share of the
  /// irradiance atlas, so that share is not counted twice; the diffuse lobe keeps the atlas.
  ///   directional_index_texture      R32I texture of the irradiance atlas's size: the element
  ///                                  index of each texel, -1 where there is none (read nearest)
  ///   directional_radiance_buffer    one DirectionalRadiance per (bin, element), bin-major
  ///   directional_direction_buffer   one DirectionalBin per bin
  ///   directional_tangent_frame      false: the bins' directions are world space; true: they
  ///                                  are in the tangent frame of each surface point's vertex
  ///                                  normal (engine::directional_tangent_frame)
  /// Empty handles / 0 counts: none.
  TextureHandle directional_index_texture;
  SsboHandle<DirectionalRadiance> directional_radiance_buffer;
  SsboHandle<DirectionalBin> directional_direction_buffer;
  int directional_bin_count = 0;
  int directional_element_count = 0;
  bool directional_tangent_frame = false;

  /// Optional reflection probes (gi fills them from baked probes, docs/reflection_probes.md):
  /// prefiltered cube maps of the static world's radiance, each with a box for parallax. On
  /// static surfaces of roughness below reflection_probe_max_roughness and on dynamic meshes
  /// without vertex_radiance_lobes, where the point lies in probes' boxes, the specular lobe's
  /// share of the indirect light is replaced (not added to) by the probes' mean radiance along
  /// the box-projected reflection direction, read at the mip of the roughness, times the
  /// lobe's directional albedo (the split sum; engine/shaders/reflection_probes.glsl).
  ///   reflection_probe_cubes   cube map array (RGBA16F), cube i = probe i, level m the
  ///                            radiance (W/(m^2 sr)) prefiltered for roughness m / (levels - 1)
  ///   reflection_probe_buffer  one ReflectionProbeBox per probe
  ///   reflection_probe_distances  optional cube map array (R32F, one level, any face size), cube i = probe
  ///                            i's distance (m) from its centre to the surface it captured per
  ///                            direction: the parallax then follows the captured surfaces (a
  ///                            distance-impostor search along the reflected ray), not the box
  ///   reflection_probe_lobe_samples  0: the split sum's one read along the reflection; 1..64:
  ///                            that many GGX samples of the lobe at a view along the normal, each
  ///                            read at the lod of its pdf (filtered importance sampling; follows
  ///                            the lobe's stretch at grazing views)
  ///   reflection_probe_lobe_samples_max  the most samples a grazing view takes (up to 64): the
  ///                            count doubles while it times cos theta_v stays below
  ///                            reflection_probe_lobe_samples; no more than that: a fixed count
  /// Empty handles / 0 counts: none.
  TextureHandle reflection_probe_cubes;
  TextureHandle reflection_probe_distances;
  SsboHandle<ReflectionProbeBox> reflection_probe_buffer;
  int reflection_probe_count = 0;
  int reflection_probe_levels = 0;
  float reflection_probe_max_roughness = 0.0f;
  int reflection_probe_lobe_samples = 0;
  int reflection_probe_lobe_samples_max = 0;

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

/// One static mesh entity's geometry as the irradiance atlas parameterizes it: the entity's
/// mesh with TEXCOORD_1 (Primitive::uv1) in the atlas. It is a whole mesh, not a UV array
/// beside the scene's: the atlas splits vertices on chart borders (a vertex on a seam has
/// one TEXCOORD_1 per chart), so its vertices and indices differ from the scene mesh's,
/// though its triangles are the same, in the same order.
///   for (const engine::AtlasMesh& a : provider.atlas_meshes()) draw a.mesh for a.entity
struct AtlasMesh {
  Entity entity;                  ///< A static entity with a MeshRenderer.
  std::uint32_t source_mesh = 0;  ///< The SceneAsset mesh it replaces (MeshRenderer::mesh).
  Mesh mesh;                      ///< Same materials and triangles, plus uv1 (vertices split at seams).
};

/// Implemented by the GI system. The renderer calls `frame()` once per rendered frame,
/// after the simulation has run, with the GL context current.
class IndirectLightProvider {
 public:
  virtual ~IndirectLightProvider() = default;
  /// Indirect light for the frame about to be drawn.
  virtual const IndirectLightFrame& frame() = 0;
  /// The static meshes the irradiance atlas is sampled on (IndirectLightFrame::
  /// irradiance_atlas_texture, directional_index_texture), owned by the provider and
  /// unchanged for its lifetime. The renderer draws an entity with its AtlasMesh while the
  /// entity's MeshRenderer::mesh is the AtlasMesh's source_mesh; other entities, and every
  /// entity when this is empty, draw the scene's mesh. Empty: no atlas geometry.
  virtual std::span<const AtlasMesh> atlas_meshes() const { return {}; }
  /// Short label for the overlay ("light atlas", "PRM", ...).
  virtual const char* label() const = 0;
};

}  // namespace engine
