#pragma once
// Plain scene data as stored in a glTF file: meshes, materials, images, lights, cameras
// and the node hierarchy. The loader fills it, the writer writes it, instantiate() turns
// it into entities. Bakers read the meshes from here, never from the registry.
//   engine::Result<engine::SceneAsset> a = engine::load_gltf("assets/cornell_box.gltf");
//   engine::Scene scene = engine::instantiate(std::move(a.value()));

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <engine/components.h>
#include <engine/sky.h>

namespace engine {

/// A decoded image, 8-bit RGBA (4 channels), rows top to bottom as in the file.
struct Image {
  std::string name;
  std::string uri;  ///< Original URI (empty for embedded images).
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba8;
};

/// How a texture's texels are addressed outside [0, 1] (glTF sampler wrapS / wrapT).
enum class TextureWrap : std::uint8_t { Repeat, ClampToEdge, MirroredRepeat };

/// glTF sampler: wrap modes and filters. glTF leaves an absent filter to the implementation;
/// the loader then picks linear with mipmaps (the default here).
struct TextureSampler {
  TextureWrap wrap_s = TextureWrap::Repeat;
  TextureWrap wrap_t = TextureWrap::Repeat;
  bool mag_linear = true;  ///< magFilter LINEAR (false: NEAREST).
  bool min_linear = true;  ///< minFilter LINEAR* (false: NEAREST*).
  bool mipmaps = true;     ///< minFilter *_MIPMAP_* (or absent): sample a mip level for the footprint.
};

/// KHR_texture_transform: uv' = translate(offset) x rotate(rotation) x scale(scale) x uv.
/// The rotation matrix is [cos sin; -sin cos] acting on (u, v): with v pointing down the
/// image (glTF's UV origin is the image's top-left corner) the UVs turn counter-clockwise
/// as seen on the image, as the extension's README example checks (offset [0, 1], rotation
/// pi/2, scale 0.5 samples the lower-left quadrant).
struct TextureTransform {
  glm::vec2 offset{0.0f};
  float rotation_rad = 0.0f;  ///< Counter-clockwise in UV space, as the extension defines it.
  glm::vec2 scale{1.0f};
};

/// A material's texture: the image, the vertex UV set it reads (TEXCOORD_n), the sampler
/// and the optional KHR_texture_transform.
struct TextureRef {
  int image = -1;    ///< Index into SceneAsset::images; -1: no texture.
  int texcoord = 0;  ///< TEXCOORD_n: 0 (Primitive::uv0) or 1 (Primitive::uv1).
  TextureSampler sampler;
  TextureTransform transform;
  bool present() const { return image >= 0; }
};

/// The UV a texture is sampled at after its KHR_texture_transform.
inline glm::vec2 transformed_uv(const TextureTransform& t, glm::vec2 uv) {
  const float c = std::cos(t.rotation_rad);
  const float s = std::sin(t.rotation_rad);
  const glm::vec2 scaled = uv * t.scale;
  return glm::vec2(c * scaled.x + s * scaled.y, -s * scaled.x + c * scaled.y) + t.offset;
}

/// glTF alphaMode: OPAQUE ignores alpha, MASK cuts out below alpha_cutoff, BLEND blends.
enum class AlphaMode : std::uint8_t { Opaque, Mask, Blend };

/// Metallic-roughness material. Colours are linear; base colour and emissive textures are
/// sRGB-encoded, the others linear. Alpha is base_color.a x the base colour texture's alpha.
struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  /// Emitted radiance, W/(m^2 sr) (glTF emissiveFactor x KHR_materials_emissive_strength).
  glm::vec3 emissive{0.0f};
  /// KHR_materials_specular: strength of the dielectric's specular layer (0: pure
  /// Lambertian) and the colour its F0 (0.04) is multiplied by. Metals ignore both.
  float specular_factor = 1.0f;
  glm::vec3 specular_color_factor{1.0f};
  TextureRef base_color_texture;          ///< RGB x base_color.rgb, A x base_color.a (sRGB).
  TextureRef metallic_roughness_texture;  ///< G x roughness, B x metallic (linear).
  TextureRef normal_texture;              ///< Tangent-space normal (linear), scaled by normal_scale.
  TextureRef emissive_texture;            ///< RGB x emissive (sRGB).
  float normal_scale = 1.0f;              ///< normalTexture.scale.
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;  ///< MASK: texels with alpha below it are cut out.
  bool double_sided = false;
};

/// One triangle list. positions are required; normals, tangents, uv0 and uv1 are empty or
/// have one entry per position. uv1 is the light-atlas parameterization (TEXCOORD_1) when
/// present.
struct Primitive {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  /// glTF TANGENT: xyz the unit tangent (direction of increasing u of the normal texture's
  /// UV set), w = +1 or -1 the handedness: bitangent = w x cross(normal, tangent). Empty:
  /// the renderer generates them where a normal texture needs them (engine/tangents.h).
  std::vector<glm::vec4> tangents;
  std::vector<glm::vec2> uv0;
  std::vector<glm::vec2> uv1;
  std::vector<std::uint32_t> indices;
  int material = -1;  ///< Index into SceneAsset::materials; -1 uses a default material.
};

struct Mesh {
  std::string name;
  std::vector<Primitive> primitives;
};

/// How GI treats a node, from the glTF node's extras ("gi": {...}, see docs/scene-format.md).
enum class Mobility : std::uint8_t { Unspecified, Static, Dynamic };

/// A region flag from the node's extras ("gi": {"region": "deforming"}): geometry that
/// deforms or opens at runtime (a door, a movable wall), which gi::plan lights with
/// antiradiance instead of baking.
enum class GiRegion : std::uint8_t { None, Deforming };

struct NodeGiFlags {
  Mobility mobility = Mobility::Unspecified;
  GiRegion region = GiRegion::None;
};

/// A node of the hierarchy. `parent` is -1 for roots; children follow from parents.
struct Node {
  std::string name;
  int parent = -1;
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  int mesh = -1;    ///< Index into SceneAsset::meshes.
  int light = -1;   ///< Index into SceneAsset::lights.
  int camera = -1;  ///< Index into SceneAsset::cameras.
  NodeGiFlags gi;
  /// Its index in the glTF file's "nodes" array; -1 when it does not come from a file (a
  /// scene built in code, the sun's node). Nodes are stored parents first, so this order
  /// can differ from theirs; engine::instantiate creates entities in it.
  int file_index = -1;
};

struct NamedLight {
  std::string name;
  Light light;  ///< Engine units (engine/units.h); `moves` comes from the node's extras.
};

struct NamedCamera {
  std::string name;
  Camera camera;
};

/// Light from outside the scene: the glTF scene's "gi" extras (docs/scene-format.md, "The
/// "gi" scene extras"). The sun is loaded as a directional light on a node of its own,
/// appended after the file's nodes, so every consumer of lights (renderer, bakers, path
/// tracer) sees it as one.
struct Environment {
  /// Uniform radiance of every direction no geometry covers, W/(m^2 sr) (0: no sky).
  glm::vec3 sky_radiance{0.0f};
  /// A gradient over the elevation added to it (engine/sky.h; all zero: none). Evaluate the
  /// sky with engine::sky_radiance(sky_radiance, sky_gradient, direction).
  SkyGradient sky_gradient;
  int sun_light = -1;  ///< Index into SceneAsset::lights of the sun, or -1.
  int sun_node = -1;   ///< Index into SceneAsset::nodes of the sun's node, or -1.
  /// Angular radius of the sun's disc (radians), also the sun light's
  /// Light::angular_radius_rad, which the bakers and the renderer read (soft shadows).
  float sun_angular_radius_rad = 0.0f;
};

/// Everything a glTF scene file holds that the engine uses.
struct SceneAsset {
  std::string source;  ///< The file it was loaded from (for messages), or empty.
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Image> images;
  std::vector<NamedLight> lights;
  std::vector<NamedCamera> cameras;
  std::vector<Node> nodes;  ///< Parents come before their children.
  Environment environment;
};

}  // namespace engine
