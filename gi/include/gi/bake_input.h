#pragma once
// What the bakers read: a scene as plain data — meshes, glTF materials, instances with
// their mobility, lights and the environment. A studio's pipeline fills it from its own
// scene format; bake_input_from() fills it from the engine's live scene. Every baker and
// the planner take this, never the ECS registry.
//   gi::BakeInput input = gi::bake_input_from(scene);          // or filled by hand
//   auto report = gi::bake_bundle(input, "out/level.gibake");  // gi/bake.h
//
// Units: metres, linear RGB, engine light units (engine/units.h). Instances place meshes
// with a matrix; a bundle remembers each static instance's `id`, which the runtime uses to
// give the matching scene mesh its light-atlas UVs (bake_input_from: the glTF node index).

#include <engine/components.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <engine/scene_asset.h>
#include <engine/sky.h>

#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// A decoded image a material's texture reads: 8-bit RGBA, rows top to bottom (engine::Image).
/// Base colour and emissive textures hold sRGB-encoded colour, the others linear data.
struct BakeImage {
  std::string name;
  std::string uri;  ///< The file it came from (empty: embedded), for messages.
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba8;  ///< width x height x 4 bytes.
};

/// A material's texture: image (index into BakeInput::images; -1 none), TEXCOORD set
/// (0: BakePrimitive::uv0, 1: uv1), sampler and KHR_texture_transform (engine/scene_asset.h).
using BakeTexture = engine::TextureRef;

/// glTF metallic-roughness material, the parameters of the one BRDF (engine/gltf_brdf.h),
/// with its textures and alpha. Every baker and the path tracer read the textures through
/// one material lookup (docs/materials-in-bakes.md): base colour (sRGB) x base_color,
/// metallic-roughness (G roughness, B metallic, linear) x the factors, emissive (sRGB) x
/// emission. The normal texture is carried but not read by the bakers (they fold surfaces
/// into diffuse reflectors at the texel's normal).
struct BakeMaterial {
  std::string name;
  glm::vec3 base_color{1.0f};              ///< Linear, in [0, 1].
  float metallic = 0.0f;                   ///< In [0, 1].
  float roughness = 1.0f;                  ///< Perceptual roughness in [0, 1].
  float specular = 1.0f;                   ///< KHR_materials_specular specularFactor in [0, 1].
  glm::vec3 specular_color{1.0f};          ///< KHR_materials_specular specularColorFactor (>= 0).
  glm::vec3 emission{0.0f};                ///< Emitted radiance of the front face, W/(m^2 sr).
  bool double_sided = false;               ///< Back faces shade and emit like front faces.
  float base_alpha = 1.0f;                 ///< base colour alpha factor, in [0, 1] (x the texture's alpha).
  BakeTexture base_color_texture;          ///< RGB x base_color, A x base_alpha (sRGB).
  BakeTexture metallic_roughness_texture;  ///< G x roughness, B x metallic (linear).
  BakeTexture emissive_texture;            ///< RGB x emission (sRGB).
  BakeTexture normal_texture;              ///< Tangent-space normal (linear); not read by the bakers.
  float normal_scale = 1.0f;
  /// Opaque ignores alpha; Mask cuts out where alpha < alpha_cutoff; Blend is baked as a
  /// cut-out at alpha 0.5 (a bake has no order to blend in; docs/materials-in-bakes.md).
  engine::AlphaMode alpha_mode = engine::AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;  ///< Mask: alpha below it is cut out, in [0, 1].

  /// True when any of the textures the bakers read is present.
  bool textured() const {
    return base_color_texture.present() || metallic_roughness_texture.present() || emissive_texture.present();
  }
  /// True when some of the surface may be cut out (Mask or Blend).
  bool cuts_out() const { return alpha_mode != engine::AlphaMode::Opaque; }
};

/// A triangle list with one material.
struct BakePrimitive {
  std::vector<glm::vec3> positions;    ///< Object space, metres.
  std::vector<glm::vec3> normals;      ///< Empty (flat shading) or one unit normal per position.
  std::vector<std::uint32_t> indices;  ///< Three per triangle, into positions.
  std::vector<glm::vec2> uv0;          ///< TEXCOORD_0: empty or one per position (material UVs).
  std::vector<glm::vec2> uv1;          ///< TEXCOORD_1: empty or one per position.
  int material = -1;                   ///< Index into BakeInput::materials; -1: glTF's default material.
};

/// A mesh: its primitives, concatenated in order wherever vertices are numbered per mesh.
struct BakeMesh {
  std::string name;
  std::vector<BakePrimitive> primitives;
};

/// How an instance takes part in baking.
enum class BakeMobility : std::uint8_t {
  Static,   ///< Never moves: baked into the light atlas and the PRM.
  Dynamic,  ///< Moves at runtime: gets basis radiance fields, casts no baked shadow.
};

/// One placement of a mesh.
struct BakeInstance {
  std::string name;
  std::uint32_t mesh = 0;           ///< Index into BakeInput::meshes.
  glm::mat4 object_to_world{1.0f};  ///< Must be finite and invertible.
  BakeMobility mobility = BakeMobility::Static;
  bool deforming = false;      ///< A region that deforms or opens (glTF gi.region "deforming").
  int material_override = -1;  ///< When >= 0, replaces every primitive's material.
  std::int64_t id = -1;        ///< The caller's id (bake_input_from: the glTF node index).
  engine::Entity entity{};     ///< The entity it was made from (bake_input_from(Scene)); null otherwise.
};

/// A light: the engine's light component (type, colour, intensity in engine units, range,
/// cone, area size; `moves` marks lights the game moves, which the PRM relights) placed by
/// a matrix. Lights emit along their local -Z. Switched-off lights (light.enabled false) may
/// be listed: the bakers skip them, the planner counts them.
struct BakeLight {
  std::string name;
  engine::Light light;
  glm::mat4 light_to_world{1.0f};
  /// A dynamic node the light is on or hangs from (bake_input_from: the nearest one up its
  /// parent chain), or empty. Such a light moves with it; the planner warns when it is not
  /// flagged `moves` (the bakers go by the flag alone).
  std::string dynamic_parent;
};

/// Light from outside the scene.
struct BakeEnvironment {
  glm::vec3 sky_radiance{0.0f};  ///< Uniform radiance of rays that leave the scene, W/(m^2 sr).
  /// Added to it: a gradient over the elevation (engine/sky.h; all zero: none). The sky of
  /// direction d is engine::sky_radiance(sky_radiance, sky_gradient, d).
  engine::SkyGradient sky_gradient;
};

/// A scene as the bakers read it.
struct BakeInput {
  std::string name;  ///< For messages and the bundle's manifest (e.g. the scene file's name).
  std::vector<BakeMesh> meshes;
  std::vector<BakeMaterial> materials;
  std::vector<BakeImage> images;  ///< What the materials' textures index.
  std::vector<BakeInstance> instances;
  std::vector<BakeLight> lights;  ///< Switched-off ones included (skipped by the bakers).
  BakeEnvironment environment;
};

/// The material of primitive `p` of `instance` (its override, its own, or glTF's default).
BakeMaterial bake_material(const BakeInput& input, const BakeInstance& instance, const BakePrimitive& p);

/// `input` with its materials' textures and alpha dropped (factors alone, Opaque) and its
/// images cleared: what the bakers saw before they read textures (gi-bake --untextured).
BakeInput without_textures(BakeInput input);

/// The live engine scene as plain data: one instance per entity with a MeshRenderer and a
/// WorldTransform (in entity order, which is node order for engine::instantiate; id = the
/// node index, or -1 for an entity made by hand), placed by its current WorldTransform,
/// Dynamic when it has DynamicTag; the materials' factors; every light (switched-off ones
/// with enabled false; `moves` as the registry has it); the scene file's name. World
/// transforms must be current.
BakeInput bake_input_from(const engine::Scene& scene);

/// The scene file as authored: one instance per node with a mesh (in node order, id = the
/// node index) at its node's world matrix, Dynamic when the node's gi mobility says so; the
/// lights of the nodes. For an instantiated, unmoved scene this equals
/// bake_input_from(engine::instantiate(asset)).
BakeInput bake_input_from(const engine::SceneAsset& asset);

/// World matrix of `node`: the product of the local TRS matrices along its parent chain
/// (bounded: a malformed chain cannot loop). Precondition: `node` indexes `asset.nodes`.
glm::mat4 node_world_matrix(const engine::SceneAsset& asset, int node);

/// Checks what the bakers rely on: mesh and material indices in range, three indices per
/// triangle within range, normals and UV sets empty or one per position, finite positions,
/// normals, UVs, matrices and light values, factors in range; every image a texture reads
/// of width x height x 4 bytes (others may be empty: a loader need not decode them); texture image indices in range and
/// the UV set a texture reads present on every primitive that uses the material. The error names the element ("mesh 3
/// 'crate' primitive 0: index 77 out of range (12 vertices)").
engine::Status validate_bake_input(const BakeInput& input);

}  // namespace gi
