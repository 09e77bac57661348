// engine::write_gltf: SceneAsset -> glTF 2.0 (.gltf + .bin, or .glb), optionally with
// KHR_draco_mesh_compression. Images are embedded as PNG in the binary buffer; each
// material's textures get a sampler (one per distinct engine::TextureSampler), their
// TEXCOORD set and KHR_texture_transform when it is not the identity. The JSON is built
// with nlohmann::json, whose objects keep their keys sorted, and floats are written in
// their shortest round-trip form, so the same input always gives the same bytes.
#include <engine/finite.h>
#include <engine/gltf.h>
#include <engine/units.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <utility>
#include <vector>
#include <nlohmann/json.hpp>

#include "gltf/draco_encode.h"
#include "gltf/gltf_file_output.h"
#include "gltf/png_encode.h"

namespace engine {
namespace {

using json = nlohmann::json;

constexpr int kFloat = 5126;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;

// The shortest decimal that reads back as the same float (0.7f -> 0.7, not 0.699999988).
json num(float f) {
  if (f == 0.0f) f = 0.0f;  // no "-0.0" in the files
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, f);
  return json(std::strtod(std::string(buf, res.ptr).c_str(), nullptr));
}
json vec(const glm::vec2& v) { return json::array({num(v.x), num(v.y)}); }
json vec(const glm::vec3& v) { return json::array({num(v.x), num(v.y), num(v.z)}); }
json vec(const glm::vec4& v) { return json::array({num(v.x), num(v.y), num(v.z), num(v.w)}); }

// The binary buffer and its bufferViews, each view aligned to 4 bytes.
class BinaryChunk {
 public:
  int add_view(const void* data, std::size_t size, int target) {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    json view = {{"buffer", 0}, {"byteOffset", bytes_.size()}, {"byteLength", size}};
    if (target != 0) view["target"] = target;
    const auto* p = static_cast<const std::uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
    views_.push_back(std::move(view));
    return static_cast<int>(views_.size()) - 1;
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }
  const json& views() const { return views_; }

 private:
  std::vector<std::uint8_t> bytes_;
  json views_ = json::array();
};

class GltfBuilder {
 public:
  GltfBuilder(const SceneAsset& scene, const std::filesystem::path& path, const GltfWriteOptions& options)
      : scene_(scene), path_(path), options_(options) {}

  Status build() {
    doc_["asset"] = {{"version", "2.0"}, {"generator", "gi engine::write_gltf"}};
    if (auto s = write_images(); !s) return s;
    if (auto s = write_materials(); !s) return s;
    write_textures();
    if (auto s = write_meshes(); !s) return s;
    write_lights();
    write_cameras();
    if (auto s = write_nodes(); !s) return s;
    if (!accessors_.empty()) doc_["accessors"] = accessors_;
    if (!bin_.views().empty()) doc_["bufferViews"] = bin_.views();
    if (!used_.empty()) doc_["extensionsUsed"] = json(std::vector<std::string>(used_.begin(), used_.end()));
    if (!required_.empty())
      doc_["extensionsRequired"] = json(std::vector<std::string>(required_.begin(), required_.end()));
    return {};
  }

  json& doc() { return doc_; }
  std::vector<std::uint8_t>& bin() { return bin_.bytes(); }

 private:
  Error error(std::string location, std::string message) const {
    return Error{path_.string(), std::move(location), std::move(message)};
  }

  int add_accessor(int view, int component_type, std::size_t count, const char* type) {
    json a = {{"componentType", component_type}, {"count", count}, {"type", type}};
    if (view >= 0) a["bufferView"] = view;
    accessors_.push_back(std::move(a));
    return static_cast<int>(accessors_.size()) - 1;
  }

  /// The images with pixels or a URI. An image with neither (an embedded image the loader
  /// could not decode and no material uses: it warned then) carries nothing to write and is
  /// left out; the others are renumbered (image_index_), and a material using a left-out
  /// image is refused in check_texture.
  Status write_images() {
    image_index_.assign(scene_.images.size(), -1);
    json images = json::array();
    for (std::size_t i = 0; i < scene_.images.size(); ++i) {
      const Image& img = scene_.images[i];
      const std::string where = "images[" + std::to_string(i) + "]";
      if (img.rgba8.empty() && img.uri.empty()) continue;
      json j;
      if (!img.name.empty()) j["name"] = img.name;
      if (!img.rgba8.empty()) {
        if (img.width <= 0 || img.height <= 0 ||
            img.rgba8.size() != static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 4)
          return error(where, "rgba8 holds " + std::to_string(img.rgba8.size()) + " bytes, not width x height x 4");
        const std::vector<std::uint8_t> png = gltf::encode_png_rgba8(img.width, img.height, img.rgba8);
        if (png.empty()) return error(where, "PNG encoding failed");
        j["bufferView"] = bin_.add_view(png.data(), png.size(), 0);
        j["mimeType"] = "image/png";
      } else {
        j["uri"] = img.uri;
      }
      image_index_[i] = static_cast<int>(images.size());
      images.push_back(std::move(j));
    }
    if (!images.empty()) doc_["images"] = std::move(images);
    return {};
  }

  /// glTF sampler enums (§5.26): wrap modes and filters.
  static int wrap_enum(TextureWrap w) {
    switch (w) {
      case TextureWrap::ClampToEdge:
        return 33071;
      case TextureWrap::MirroredRepeat:
        return 33648;
      case TextureWrap::Repeat:
        break;
    }
    return 10497;
  }
  static json sampler_json(const TextureSampler& s) {
    const int min_filter = s.mipmaps ? (s.min_linear ? 9987 : 9986)   // LINEAR_ / NEAREST_MIPMAP_LINEAR
                                     : (s.min_linear ? 9729 : 9728);  // LINEAR / NEAREST
    return {{"wrapS", wrap_enum(s.wrap_s)},
            {"wrapT", wrap_enum(s.wrap_t)},
            {"magFilter", s.mag_linear ? 9729 : 9728},
            {"minFilter", min_filter}};
  }
  static bool same_sampler(const TextureSampler& a, const TextureSampler& b) {
    return a.wrap_s == b.wrap_s && a.wrap_t == b.wrap_t && a.mag_linear == b.mag_linear &&
           a.min_linear == b.min_linear && a.mipmaps == b.mipmaps;
  }

  /// The glTF texture (image + sampler) for `t`, added on first use: one sampler per
  /// distinct TextureSampler, one texture per distinct (image, sampler) pair, in the order
  /// the materials first use them.
  int texture_index(const TextureRef& t) {
    auto s = std::find_if(samplers_.begin(), samplers_.end(),
                          [&](const TextureSampler& o) { return same_sampler(o, t.sampler); });
    if (s == samplers_.end()) s = samplers_.insert(samplers_.end(), t.sampler);
    const std::pair<int, int> key{t.image, static_cast<int>(s - samplers_.begin())};
    auto k = std::find(textures_.begin(), textures_.end(), key);
    if (k == textures_.end()) k = textures_.insert(textures_.end(), key);
    return static_cast<int>(k - textures_.begin());
  }

  Status check_texture(const TextureRef& t, const std::string& where) const {
    if (t.image >= static_cast<int>(scene_.images.size()))
      return error(where, "image " + std::to_string(t.image) + " is out of range (" +
                              std::to_string(scene_.images.size()) + " images)");
    if (t.image >= 0 && image_index_[static_cast<std::size_t>(t.image)] < 0)
      return error(where, "image " + std::to_string(t.image) + " has neither pixels nor a URI");
    if (t.texcoord < 0) return error(where, "texcoord must be >= 0, got " + std::to_string(t.texcoord));
    const TextureTransform& x = t.transform;
    if (!engine::all_finite(x.offset) || !engine::all_finite(x.scale) || !std::isfinite(x.rotation_rad))
      return error(where, "texture transform is NaN or infinite");
    return {};
  }

  /// A textureInfo: index, texCoord (when not 0) and KHR_texture_transform (when not the identity).
  json texture_info(const TextureRef& t) {
    json j = {{"index", texture_index(t)}};
    if (t.texcoord != 0) j["texCoord"] = t.texcoord;
    const TextureTransform& x = t.transform;
    json transform = json::object();
    if (x.offset != glm::vec2(0.0f)) transform["offset"] = vec(x.offset);
    if (x.rotation_rad != 0.0f) transform["rotation"] = num(x.rotation_rad);
    if (x.scale != glm::vec2(1.0f)) transform["scale"] = vec(x.scale);
    if (!transform.empty()) {
      j["extensions"]["KHR_texture_transform"] = std::move(transform);
      used_.insert("KHR_texture_transform");
    }
    return j;
  }

  Status write_materials() {
    if (scene_.materials.empty()) return {};
    json materials = json::array();
    for (std::size_t i = 0; i < scene_.materials.size(); ++i) {
      const Material& m = scene_.materials[i];
      const std::string where = "materials[" + std::to_string(i) + "]";
      for (const auto& [ref, name] :
           {std::pair{&m.base_color_texture, "baseColorTexture"},
            std::pair{&m.metallic_roughness_texture, "metallicRoughnessTexture"},
            std::pair{&m.normal_texture, "normalTexture"}, std::pair{&m.emissive_texture, "emissiveTexture"}})
        if (auto s = check_texture(*ref, where + " " + name); !s) return s;
      if (!std::isfinite(m.alpha_cutoff) || m.alpha_cutoff < 0.0f)
        return error(where, "alphaCutoff must be a finite number >= 0");
      if (!std::isfinite(m.normal_scale)) return error(where, "normal texture scale is NaN or infinite");
      json pbr = {{"baseColorFactor", vec(m.base_color)},
                  {"metallicFactor", num(m.metallic)},
                  {"roughnessFactor", num(m.roughness)}};
      if (m.base_color_texture.present()) pbr["baseColorTexture"] = texture_info(m.base_color_texture);
      if (m.metallic_roughness_texture.present())
        pbr["metallicRoughnessTexture"] = texture_info(m.metallic_roughness_texture);
      json j = {{"pbrMetallicRoughness", std::move(pbr)}};
      if (!m.name.empty()) j["name"] = m.name;
      if (m.normal_texture.present()) {
        j["normalTexture"] = texture_info(m.normal_texture);
        if (m.normal_scale != 1.0f) j["normalTexture"]["scale"] = num(m.normal_scale);
      }
      if (m.emissive_texture.present()) j["emissiveTexture"] = texture_info(m.emissive_texture);
      const float peak = std::max({m.emissive.x, m.emissive.y, m.emissive.z});
      if (peak > 1.0f) {
        // glTF clamps emissiveFactor to [0,1]; the rest goes into the strength.
        j["emissiveFactor"] = vec(m.emissive / peak);
        j["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", num(peak)}};
        used_.insert("KHR_materials_emissive_strength");
      } else if (peak > 0.0f) {
        j["emissiveFactor"] = vec(m.emissive);
      }
      if (m.specular_factor != 1.0f || m.specular_color_factor != glm::vec3(1.0f)) {
        j["extensions"]["KHR_materials_specular"] = {{"specularFactor", num(m.specular_factor)},
                                                     {"specularColorFactor", vec(m.specular_color_factor)}};
        used_.insert("KHR_materials_specular");
      }
      // Defaults (OPAQUE, cutoff 0.5) are left out; glTF ignores alphaCutoff unless MASK.
      if (m.alpha_mode == AlphaMode::Mask) {
        j["alphaMode"] = "MASK";
        if (m.alpha_cutoff != 0.5f) j["alphaCutoff"] = num(m.alpha_cutoff);
      } else if (m.alpha_mode == AlphaMode::Blend) {
        j["alphaMode"] = "BLEND";
      }
      if (m.double_sided) j["doubleSided"] = true;
      materials.push_back(std::move(j));
    }
    doc_["materials"] = std::move(materials);
    return {};
  }

  /// The textures and samplers the materials use (texture_index collected them).
  void write_textures() {
    if (textures_.empty()) return;
    json samplers = json::array();
    for (const TextureSampler& s : samplers_) samplers.push_back(sampler_json(s));
    json textures = json::array();
    for (const auto& [image, sampler] : textures_)
      textures.push_back({{"source", image_index_[static_cast<std::size_t>(image)]}, {"sampler", sampler}});
    doc_["samplers"] = std::move(samplers);
    doc_["textures"] = std::move(textures);
  }

  Status check_primitive(const Primitive& p, const std::string& where) const {
    const std::size_t n = p.positions.size();
    if (n == 0) return error(where, "primitive has no positions");
    if (n > 0xFFFFFFFFu) return error(where, "too many vertices for 32-bit indices");
    if (!p.normals.empty() && p.normals.size() != n) return error(where, "normals count differs from positions count");
    if (!p.uv0.empty() && p.uv0.size() != n) return error(where, "uv0 count differs from positions count");
    if (!p.uv1.empty() && p.uv1.size() != n) return error(where, "uv1 count differs from positions count");
    if (!p.tangents.empty() && p.tangents.size() != n)
      return error(where, "tangents count differs from positions count");
    for (const glm::vec4& t : p.tangents)
      if (!engine::all_finite(t)) return error(where, "tangent is NaN or infinite");
    if (p.indices.size() % 3 != 0) return error(where, "index count is not a multiple of 3");
    if (p.indices.empty() && n % 3 != 0) return error(where, "non-indexed vertex count is not a multiple of 3");
    for (std::uint32_t i : p.indices)
      if (i >= n) return error(where, "index " + std::to_string(i) + " out of range");
    for (const glm::vec3& v : p.positions)
      if (!engine::all_finite(v)) return error(where, "position is NaN or infinite");
    for (const glm::vec3& v : p.normals)
      if (!engine::all_finite(v)) return error(where, "normal is NaN or infinite");
    for (const std::vector<glm::vec2>* uvs : {&p.uv0, &p.uv1})
      for (const glm::vec2& v : *uvs)
        if (!engine::all_finite(v)) return error(where, "texture coordinate is NaN or infinite");
    if (p.material >= static_cast<int>(scene_.materials.size())) return error(where, "material index out of range");
    return {};
  }

  template <class T>
  int add_attribute(const std::vector<T>& values, const char* type) {
    const int view = bin_.add_view(values.data(), values.size() * sizeof(T), kArrayBuffer);
    return add_accessor(view, kFloat, values.size(), type);
  }

  int add_indices(const std::vector<std::uint32_t>& indices, std::size_t vertex_count) {
    if (vertex_count <= 0xFFFF) {
      std::vector<std::uint16_t> shorts(indices.begin(), indices.end());
      const int view = bin_.add_view(shorts.data(), shorts.size() * 2, kElementArrayBuffer);
      return add_accessor(view, kUnsignedShort, shorts.size(), "SCALAR");
    }
    const int view = bin_.add_view(indices.data(), indices.size() * 4, kElementArrayBuffer);
    return add_accessor(view, kUnsignedInt, indices.size(), "SCALAR");
  }

  json plain_primitive(const Primitive& p) {
    json attributes;
    const int pos = add_attribute(p.positions, "VEC3");
    glm::vec3 lo = p.positions[0], hi = p.positions[0];
    for (const glm::vec3& v : p.positions) {
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    accessors_[static_cast<std::size_t>(pos)]["min"] = vec(lo);
    accessors_[static_cast<std::size_t>(pos)]["max"] = vec(hi);
    attributes["POSITION"] = pos;
    if (!p.normals.empty()) attributes["NORMAL"] = add_attribute(p.normals, "VEC3");
    if (!p.uv0.empty()) attributes["TEXCOORD_0"] = add_attribute(p.uv0, "VEC2");
    if (!p.uv1.empty()) attributes["TEXCOORD_1"] = add_attribute(p.uv1, "VEC2");
    if (!p.tangents.empty()) attributes["TANGENT"] = add_attribute(p.tangents, "VEC4");
    json j = {{"attributes", std::move(attributes)}, {"mode", 4}};
    if (!p.indices.empty()) j["indices"] = add_indices(p.indices, p.positions.size());
    return j;
  }

  Status draco_primitive(const Primitive& p, const std::string& where, json& out) {
    gltf::DracoPrimitive d;
    std::string message;
    const gltf::DracoQuantization bits{options_.draco_position_bits, options_.draco_normal_bits,
                                       options_.draco_texcoord_bits};
    if (!gltf::encode_draco_primitive(p, bits, d, message)) return error(where, message);
    const int view = bin_.add_view(d.bytes.data(), d.bytes.size(), 0);
    json attributes;
    json ids;
    const int pos = add_accessor(-1, kFloat, d.vertex_count, "VEC3");
    accessors_[static_cast<std::size_t>(pos)]["min"] = vec(d.position_min);
    accessors_[static_cast<std::size_t>(pos)]["max"] = vec(d.position_max);
    attributes["POSITION"] = pos;
    ids["POSITION"] = d.position_id;
    if (d.normal_id >= 0) {
      attributes["NORMAL"] = add_accessor(-1, kFloat, d.vertex_count, "VEC3");
      ids["NORMAL"] = d.normal_id;
    }
    if (d.uv0_id >= 0) {
      attributes["TEXCOORD_0"] = add_accessor(-1, kFloat, d.vertex_count, "VEC2");
      ids["TEXCOORD_0"] = d.uv0_id;
    }
    if (d.uv1_id >= 0) {
      attributes["TEXCOORD_1"] = add_accessor(-1, kFloat, d.vertex_count, "VEC2");
      ids["TEXCOORD_1"] = d.uv1_id;
    }
    out = {{"attributes", std::move(attributes)}, {"mode", 4}};
    out["indices"] =
        add_accessor(-1, d.vertex_count <= 0xFFFF ? kUnsignedShort : kUnsignedInt, d.index_count, "SCALAR");
    out["extensions"]["KHR_draco_mesh_compression"] = {{"bufferView", view}, {"attributes", std::move(ids)}};
    used_.insert("KHR_draco_mesh_compression");
    required_.insert("KHR_draco_mesh_compression");
    return {};
  }

  Status write_meshes() {
    if (scene_.meshes.empty()) return {};
    json meshes = json::array();
    mesh_index_.assign(scene_.meshes.size(), -1);
    for (std::size_t m = 0; m < scene_.meshes.size(); ++m) {
      const Mesh& mesh = scene_.meshes[m];
      json prims = json::array();
      for (std::size_t k = 0; k < mesh.primitives.size(); ++k) {
        const Primitive& p = mesh.primitives[k];
        const std::string where = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(k) + "]";
        if (auto s = check_primitive(p, where); !s) return s;
        json j;
        if (options_.draco) {
          if (auto s = draco_primitive(p, where, j); !s) return s;
        } else {
          j = plain_primitive(p);
        }
        if (p.material >= 0) j["material"] = p.material;
        prims.push_back(std::move(j));
      }
      // A mesh the loader kept without drawable primitives (only points or lines, or unused
      // and undecodable) has nothing to write, and glTF wants at least one primitive: it is
      // left out and its nodes keep no mesh (found by fuzz_gltf: the scene loaded, the write failed).
      if (prims.empty()) continue;
      mesh_index_[m] = static_cast<int>(meshes.size());
      json j = {{"primitives", std::move(prims)}};
      if (!mesh.name.empty()) j["name"] = mesh.name;
      meshes.push_back(std::move(j));
    }
    if (!meshes.empty()) doc_["meshes"] = std::move(meshes);
    return {};
  }

  void write_lights() {
    json lights = json::array();
    khr_light_index_.assign(scene_.lights.size(), -1);
    for (std::size_t i = 0; i < scene_.lights.size(); ++i) {
      const Light& l = scene_.lights[i].light;
      if (l.type == LightType::Area) continue;                                               // written as node extras
      if (sun_in_extras() && static_cast<int>(i) == scene_.environment.sun_light) continue;  // scene extras
      json j = {{"color", vec(l.color)}};
      if (!scene_.lights[i].name.empty()) j["name"] = scene_.lights[i].name;
      switch (l.type) {
        case LightType::Point:
          j["type"] = "point";
          j["intensity"] = num(units::w_per_sr_to_candela(l.intensity));
          break;
        case LightType::Spot:
          j["type"] = "spot";
          j["intensity"] = num(units::w_per_sr_to_candela(l.intensity));
          j["spot"] = {{"innerConeAngle", num(l.inner_cone_rad)}, {"outerConeAngle", num(l.outer_cone_rad)}};
          break;
        case LightType::Directional:
          j["type"] = "directional";
          j["intensity"] = num(units::w_per_m2_to_lux(l.intensity));
          break;
        case LightType::Area:
          break;
      }
      if (l.type != LightType::Directional && l.range_m > 0.0f) j["range"] = num(l.range_m);
      khr_light_index_[i] = static_cast<int>(lights.size());
      lights.push_back(std::move(j));
    }
    if (lights.empty()) return;
    doc_["extensions"]["KHR_lights_punctual"] = {{"lights", std::move(lights)}};
    used_.insert("KHR_lights_punctual");
  }

  void write_cameras() {
    if (scene_.cameras.empty()) return;
    json cameras = json::array();
    for (const NamedCamera& c : scene_.cameras) {
      json persp = {{"yfov", num(c.camera.yfov_rad)}, {"znear", num(c.camera.znear_m)}};
      if (c.camera.zfar_m > 0.0f && std::isfinite(c.camera.zfar_m)) persp["zfar"] = num(c.camera.zfar_m);
      if (c.camera.aspect > 0.0f) persp["aspectRatio"] = num(c.camera.aspect);
      json j = {{"type", "perspective"}, {"perspective", std::move(persp)}};
      if (!c.name.empty()) j["name"] = c.name;
      cameras.push_back(std::move(j));
    }
    doc_["cameras"] = std::move(cameras);
  }

  /// The environment's sun is written back as the scene's gi.sun when it is what the loader
  /// made of one: a root directional light on the last node, with no children. Otherwise
  /// (the scene was edited) it stays an ordinary directional light node.
  bool sun_in_extras() const {
    const Environment& env = scene_.environment;
    if (env.sun_node < 0 || env.sun_node + 1 != static_cast<int>(scene_.nodes.size())) return false;
    if (env.sun_light < 0 || env.sun_light >= static_cast<int>(scene_.lights.size())) return false;
    const Node& n = scene_.nodes[static_cast<std::size_t>(env.sun_node)];
    for (const Node& other : scene_.nodes)
      if (&other != &n && other.light == env.sun_light) return false;
    return n.parent < 0 && n.light == env.sun_light && n.mesh < 0 && n.camera < 0 &&
           scene_.lights[static_cast<std::size_t>(env.sun_light)].light.type == LightType::Directional;
  }

  /// The scene's "gi" extras: sky and sun (docs/scene-format.md).
  json scene_extras() const {
    const Environment& env = scene_.environment;
    json gi = json::object();
    if (env.sky_radiance != glm::vec3(0.0f)) gi["sky"] = {{"radiance", vec(env.sky_radiance)}};
    if (!env.sky_gradient.empty()) {
      if (!gi.contains("sky")) gi["sky"] = json::object();
      gi["sky"]["zenith"] = vec(env.sky_gradient.zenith);
      gi["sky"]["horizon"] = vec(env.sky_gradient.horizon);
      gi["sky"]["ground"] = vec(env.sky_gradient.ground);
    }
    if (sun_in_extras()) {
      const Node& n = scene_.nodes[static_cast<std::size_t>(env.sun_node)];
      const Light& l = scene_.lights[static_cast<std::size_t>(env.sun_light)].light;
      gi["sun"] = {{"direction", vec(n.rotation * glm::vec3(0.0f, 0.0f, -1.0f))},
                   {"irradiance", vec(l.color * l.intensity)},
                   {"angular_radius_deg", num(env.sun_angular_radius_rad * 57.29577951308232f)}};
    }
    return gi;
  }

  Status write_nodes() {
    const int count = static_cast<int>(scene_.nodes.size()) - (sun_in_extras() ? 1 : 0);
    std::vector<json> children(scene_.nodes.size(), json::array());
    json roots = json::array();
    for (int i = 0; i < count; ++i) {
      const int parent = scene_.nodes[static_cast<std::size_t>(i)].parent;
      if (parent >= i) return error("nodes[" + std::to_string(i) + "]", "parent must come before its child");
      if (parent < 0)
        roots.push_back(i);
      else
        children[static_cast<std::size_t>(parent)].push_back(i);
    }
    json nodes = json::array();
    for (int i = 0; i < count; ++i) {
      const Node& n = scene_.nodes[static_cast<std::size_t>(i)];
      const std::string where = "nodes[" + std::to_string(i) + "]";
      json j = json::object();  // a bare node (no name, identity, nothing attached) is {}, not null
      if (!n.name.empty()) j["name"] = n.name;
      if (!engine::all_finite(n.translation) || !engine::all_finite(n.scale) || !std::isfinite(n.rotation.w) ||
          !engine::all_finite(glm::vec3(n.rotation.x, n.rotation.y, n.rotation.z)))
        return error(where, "transform is NaN or infinite");
      if (n.translation != glm::vec3(0.0f)) j["translation"] = vec(n.translation);
      if (n.rotation != glm::quat(1.0f, 0.0f, 0.0f, 0.0f))
        j["rotation"] = json::array({num(n.rotation.x), num(n.rotation.y), num(n.rotation.z), num(n.rotation.w)});
      if (n.scale != glm::vec3(1.0f)) j["scale"] = vec(n.scale);
      if (!children[static_cast<std::size_t>(i)].empty()) j["children"] = children[static_cast<std::size_t>(i)];
      if (n.mesh >= static_cast<int>(scene_.meshes.size())) return error(where, "mesh index out of range");
      if (n.camera >= static_cast<int>(scene_.cameras.size())) return error(where, "camera index out of range");
      if (n.light >= static_cast<int>(scene_.lights.size())) return error(where, "light index out of range");
      if (n.mesh >= 0 && mesh_index_[static_cast<std::size_t>(n.mesh)] >= 0)
        j["mesh"] = mesh_index_[static_cast<std::size_t>(n.mesh)];
      if (n.camera >= 0) j["camera"] = n.camera;
      json gi = json::object();
      if (n.gi.mobility == Mobility::Static) gi["mobility"] = "static";
      if (n.gi.mobility == Mobility::Dynamic) gi["mobility"] = "dynamic";
      if (n.gi.region == GiRegion::Deforming) gi["region"] = "deforming";
      if (n.light >= 0) {
        const Light& l = scene_.lights[static_cast<std::size_t>(n.light)].light;
        gi["light_moves"] = l.moves;
        if (l.type == LightType::Area) {
          gi["area_light"] = {{"size_m", vec(l.area_size_m)}, {"radiance", vec(l.color * l.intensity)}};
        } else {
          j["extensions"]["KHR_lights_punctual"] = {{"light", khr_light_index_[static_cast<std::size_t>(n.light)]}};
        }
      }
      if (!gi.empty()) j["extras"]["gi"] = std::move(gi);
      nodes.push_back(std::move(j));
    }
    if (!nodes.empty()) doc_["nodes"] = std::move(nodes);
    json scene = {{"nodes", std::move(roots)}};
    if (json gi = scene_extras(); !gi.empty()) scene["extras"]["gi"] = std::move(gi);
    doc_["scenes"] = json::array({std::move(scene)});
    doc_["scene"] = 0;
    return {};
  }

  const SceneAsset& scene_;
  const std::filesystem::path& path_;
  const GltfWriteOptions& options_;
  json doc_ = json::object();
  json accessors_ = json::array();
  BinaryChunk bin_;
  std::vector<int> khr_light_index_;
  std::vector<int> mesh_index_;                ///< SceneAsset mesh -> written mesh, -1 when left out (no primitives).
  std::vector<int> image_index_;               ///< scene image -> written image (-1: left out).
  std::vector<TextureSampler> samplers_;       ///< Distinct samplers, in order of first use.
  std::vector<std::pair<int, int>> textures_;  ///< (image, sampler) per glTF texture.
  std::set<std::string> used_;
  std::set<std::string> required_;
};

}  // namespace

Status write_gltf(const SceneAsset& scene, const std::filesystem::path& path, const GltfWriteOptions& options) {
  GltfBuilder builder(scene, path, options);
  if (auto s = builder.build(); !s) return s;
  const bool binary = options.binary || path.extension() == ".glb";
  std::vector<std::uint8_t>& bin = builder.bin();
  json& doc = builder.doc();
  if (binary) {
    if (!bin.empty()) doc["buffers"] = json::array({{{"byteLength", bin.size()}}});
    return gltf::write_files_atomically({{path, gltf::make_glb(doc.dump(), bin)}});
  }
  std::vector<gltf::OutputFile> files;
  if (!bin.empty()) {
    std::filesystem::path bin_path = path;
    bin_path.replace_extension(".bin");
    doc["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", bin_path.filename().string()}}});
    files.push_back({bin_path, std::move(bin)});
  }
  std::string text = doc.dump(1) + "\n";
  files.push_back({path, std::vector<std::uint8_t>(text.begin(), text.end())});
  return gltf::write_files_atomically(files);
}

}  // namespace engine
