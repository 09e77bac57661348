// Materials and images of the glTF loader: metallic-roughness factors and textures
// (glTF 2.0 §3.9), emissive strength (KHR_materials_emissive_strength), images decoded to
// RGBA8 with stb_image. A missing or undecodable image is an error naming its URI: a game
// must not ship a broken texture silently (docs/scene-format.md).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <stb_image.h>  // compiled in tinygltf_impl.cpp (STB_IMAGE_IMPLEMENTATION)

#include <engine/log.h>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {

bool decode_image_callback(tinygltf::Image* image, int image_idx, std::string* /*err*/, std::string* /*warn*/,
                           int /*req_width*/, int /*req_height*/, const unsigned char* bytes, int size,
                           void* user_data) {
  auto* state = static_cast<ImageDecodeState*>(user_data);
  if (image_idx < 0 || static_cast<std::size_t>(image_idx) >= state->delivered.size()) return false;
  const auto idx = static_cast<std::size_t>(image_idx);
  state->delivered[idx] = true;
  if (!state->decode || idx >= state->used.size() || !state->used[idx]) return true;  // unused: not decoded
  if (bytes == nullptr || size <= 0) {
    state->failures[idx] = "image data is empty";
    return true;
  }
  int w = 0;
  int h = 0;
  int channels = 0;
  if (stbi_info_from_memory(bytes, size, &w, &h, &channels) == 0) {
    state->failures[idx] = std::string("cannot decode image: ") + stbi_failure_reason();
    return true;
  }
  if (w <= 0 || h <= 0 || w > state->max_dimension || h > state->max_dimension) {
    state->failures[idx] = "image of " + std::to_string(w) + "x" + std::to_string(h) + " pixels exceeds the limit of " +
                           std::to_string(state->max_dimension);
    return true;
  }
  // Budgets from the header, before a byte is decoded (GltfLoadLimits).
  const std::size_t pixels_needed = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (pixels_needed > state->max_pixels) {
    state->failures[idx] = "image of " + std::to_string(w) + "x" + std::to_string(h) + " = " +
                           std::to_string(pixels_needed) + " pixels exceeds the per-image budget of " +
                           std::to_string(state->max_pixels) + " pixels (GltfLoadLimits::max_image_pixels)";
    return true;
  }
  const std::size_t bytes_needed = pixels_needed * 4;
  if (bytes_needed > state->max_total_bytes || state->decoded_bytes > state->max_total_bytes - bytes_needed) {
    state->failures[idx] = "decoding this " + std::to_string(w) + "x" + std::to_string(h) + " image (" +
                           std::to_string(bytes_needed) + " bytes) would bring the scene's decoded images to " +
                           std::to_string(state->decoded_bytes + bytes_needed) + " bytes, over the budget of " +
                           std::to_string(state->max_total_bytes) + " (GltfLoadLimits::max_scene_image_bytes)";
    return true;
  }
  state->decoded_bytes += bytes_needed;
  unsigned char* pixels = stbi_load_from_memory(bytes, size, &w, &h, &channels, 4);
  if (pixels == nullptr) {
    state->failures[idx] = std::string("cannot decode image: ") + stbi_failure_reason();
    return true;
  }
  image->width = w;
  image->height = h;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(pixels, pixels + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  stbi_image_free(pixels);
  return true;
}

namespace {
Status image_status(const Context& ctx, const ParsedFile& file, int image);
}  // namespace

Result<std::vector<Image>> convert_images(const Context& ctx, const ParsedFile& file) {
  std::vector<Image> images;
  images.reserve(file.model.images.size());
  for (std::size_t i = 0; i < file.model.images.size(); ++i) {
    const tinygltf::Image& src = file.model.images[i];
    const bool used = i < file.images.used.size() && file.images.used[i];
    if (auto ok = image_status(ctx, file, static_cast<int>(i)); !ok && !used) {
      // Only images that materials use must load (checked there); others are reported.
      log_message(LogLevel::Warning, ok.error().to_string() + " (unused by materials)");
    }
    Image img;
    img.name = src.name;
    img.uri = src.uri;
    if (ctx.options.load_images && !src.image.empty()) {  // decoded (images no material uses are not)
      img.width = src.width;
      img.height = src.height;
      img.rgba8 = src.image;
    }
    images.push_back(std::move(img));
  }
  return images;
}

namespace {

/// An image a material uses must be there and decode: a broken texture is an error.
Status image_status(const Context& ctx, const ParsedFile& file, int image) {
  if (image < 0) return {};
  const auto i = static_cast<std::size_t>(image);
  const std::string& uri = file.model.images[i].uri;
  const std::string where = "image " + std::to_string(image) + (uri.empty() ? "" : " '" + uri + "'");
  if (i >= file.images.delivered.size() || !file.images.delivered[i]) {
    return ctx.error(where, "image file is missing or unreadable");
  }
  if (!file.images.failures[i].empty()) return ctx.error(where, file.images.failures[i]);
  return {};
}

/// Texture index -> image index (texture.source); -1 when the texture has no core source
/// (e.g. only an extension's image format).
Result<int> texture_image(const Context& ctx, const ParsedFile& file, int texture, const std::string& where) {
  const tinygltf::Model& model = file.model;
  if (texture < 0) return -1;
  if (static_cast<std::size_t>(texture) >= model.textures.size()) {
    return ctx.error(where, "texture " + std::to_string(texture) + " is out of range (" +
                                std::to_string(model.textures.size()) + " textures)");
  }
  const int source = model.textures[static_cast<std::size_t>(texture)].source;
  if (source >= 0 && static_cast<std::size_t>(source) >= model.images.size()) {
    return ctx.error("texture " + std::to_string(texture),
                     "source image " + std::to_string(source) + " is out of range");
  }
  if (auto ok = image_status(ctx, file, source); !ok) return ok.error();
  return source;
}

Result<float> unit_factor(const Context& ctx, double v, const std::string& where, const char* name) {
  if (!std::isfinite(v) || v < 0.0 || v > 1.0) {
    return ctx.error(where, std::string(name) + " must be in [0, 1], got " + std::to_string(v));
  }
  return static_cast<float>(v);
}

// KHR_materials_specular's factors: specularFactor in [0, 1] (0: no specular layer, a pure
// Lambertian dielectric), specularColorFactor >= 0 per channel (the BRDF clamps 0.04 x it to
// 1). Its textures are not read: the factors alone apply.
Status read_specular_extension(const Context& ctx, const Json* exts, const std::string& where, Material& m) {
  const Json* ext = exts != nullptr ? find_member(*exts, "KHR_materials_specular") : nullptr;
  if (ext == nullptr) return {};
  const std::string at = where + " KHR_materials_specular";
  auto factor = number_member(ctx, *ext, "specularFactor", 1.0, at);
  if (!factor) return factor.error();
  auto weight = unit_factor(ctx, *factor, at, "specularFactor");
  if (!weight) return weight.error();
  m.specular_factor = *weight;
  const Json* color = find_member(*ext, "specularColorFactor");
  if (color == nullptr) return {};
  if (!color->is_array() || color->size() != 3)
    return ctx.error(at, "specularColorFactor must be an array of 3 numbers");
  for (std::size_t c = 0; c < 3; ++c) {
    const Json& v = (*color)[c];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0.0 || v.get<double>() > 1e6) {
      return ctx.error(at, "specularColorFactor components must be finite numbers in [0, 1e6]");
    }
    m.specular_color_factor[static_cast<glm::length_t>(c)] = static_cast<float>(v.get<double>());
  }
  return {};
}

// glTF sampler enums (§5.26).
constexpr int kNearest = 9728;
constexpr int kLinear = 9729;
constexpr int kNearestMipmapNearest = 9984;
constexpr int kLinearMipmapLinear = 9987;
constexpr int kClampToEdge = 33071;
constexpr int kMirroredRepeat = 33648;
constexpr int kRepeat = 10497;

Result<TextureWrap> wrap_mode(const Context& ctx, int value, const std::string& where, const char* name) {
  switch (value) {
    case kRepeat:
    case -1:  // absent: REPEAT (§5.26.4)
      return TextureWrap::Repeat;
    case kClampToEdge:
      return TextureWrap::ClampToEdge;
    case kMirroredRepeat:
      return TextureWrap::MirroredRepeat;
    default:
      return ctx.error(where, std::string(name) + " " + std::to_string(value) + " is not a glTF wrap mode");
  }
}

/// The texture's sampler (texture.sampler), or the defaults: repeat, linear with mipmaps
/// (glTF leaves absent filters to the implementation, §5.26).
Result<TextureSampler> texture_sampler(const Context& ctx, const ParsedFile& file, int texture) {
  TextureSampler out;
  const int index = file.model.textures[static_cast<std::size_t>(texture)].sampler;
  if (index < 0) return out;
  if (static_cast<std::size_t>(index) >= file.model.samplers.size()) {
    return ctx.error("texture " + std::to_string(texture), "sampler " + std::to_string(index) + " is out of range");
  }
  const tinygltf::Sampler& src = file.model.samplers[static_cast<std::size_t>(index)];
  const std::string where = "sampler " + std::to_string(index);
  auto s = wrap_mode(ctx, src.wrapS, where, "wrapS");
  if (!s) return s.error();
  auto t = wrap_mode(ctx, src.wrapT, where, "wrapT");
  if (!t) return t.error();
  out.wrap_s = *s;
  out.wrap_t = *t;
  if (src.magFilter != -1 && src.magFilter != kNearest && src.magFilter != kLinear) {
    return ctx.error(where, "magFilter " + std::to_string(src.magFilter) + " is not NEAREST or LINEAR");
  }
  out.mag_linear = src.magFilter != kNearest;
  if (src.minFilter != -1 && src.minFilter != kNearest && src.minFilter != kLinear &&
      (src.minFilter < kNearestMipmapNearest || src.minFilter > kLinearMipmapLinear)) {
    return ctx.error(where, "minFilter " + std::to_string(src.minFilter) + " is not a glTF minification filter");
  }
  // 9984 NEAREST_MIPMAP_NEAREST, 9985 LINEAR_MIPMAP_NEAREST, 9986 NEAREST_MIPMAP_LINEAR,
  // 9987 LINEAR_MIPMAP_LINEAR: bit 0 says linear within a level. Between levels the
  // renderer always blends (the *_MIPMAP_NEAREST forms differ only in that).
  out.mipmaps = src.minFilter == -1 || src.minFilter >= kNearestMipmapNearest;
  out.min_linear = src.minFilter == -1 || src.minFilter == kLinear ||
                   (src.minFilter >= kNearestMipmapNearest && (src.minFilter - kNearestMipmapNearest) % 2 == 1);
  return out;
}

/// A finite number array of `n` components, or an error.
Result<glm::vec2> vec2_member(const Context& ctx, const Json& object, const char* key, glm::vec2 fallback,
                              const std::string& where) {
  const Json* v = find_member(object, key);
  if (v == nullptr) return fallback;
  if (!v->is_array() || v->size() != 2 || !(*v)[0].is_number() || !(*v)[1].is_number()) {
    return ctx.error(where, std::string("'") + key + "' must be an array of 2 numbers");
  }
  const glm::vec2 out((*v)[0].get<double>(), (*v)[1].get<double>());
  if (!std::isfinite(out.x) || !std::isfinite(out.y)) {
    return ctx.error(where, std::string("'") + key + "' must be finite");
  }
  return out;
}

/// KHR_texture_transform on a textureInfo: offset, rotation, scale and its texCoord override.
Status read_texture_transform(const Context& ctx, const Json& info, const std::string& where, TextureRef& ref) {
  const Json* exts = find_member(info, "extensions");
  const Json* ext = exts != nullptr ? find_member(*exts, "KHR_texture_transform") : nullptr;
  if (ext == nullptr) return {};
  const std::string at = where + " KHR_texture_transform";
  if (!ext->is_object()) return ctx.error(at, "must be an object");
  auto offset = vec2_member(ctx, *ext, "offset", glm::vec2(0.0f), at);
  if (!offset) return offset.error();
  auto scale = vec2_member(ctx, *ext, "scale", glm::vec2(1.0f), at);
  if (!scale) return scale.error();
  auto rotation = number_member(ctx, *ext, "rotation", 0.0, at);
  if (!rotation) return rotation.error();
  if (!std::isfinite(static_cast<float>(*rotation))) return ctx.error(at, "'rotation' must be finite");
  ref.transform.offset = *offset;
  ref.transform.scale = *scale;
  ref.transform.rotation_rad = static_cast<float>(*rotation);
  if (const Json* tc = find_member(*ext, "texCoord"); tc != nullptr) {
    if (!tc->is_number_integer()) return ctx.error(at, "'texCoord' must be an integer");
    ref.texcoord = static_cast<int>(std::clamp<std::int64_t>(tc->get<std::int64_t>(), -1, 1 << 20));
  }
  return {};
}

/// One textureInfo of material `where`: its image, TEXCOORD set (0 or 1: the engine's
/// vertices carry two), sampler and KHR_texture_transform.
Status read_texture_ref(const Context& ctx, const ParsedFile& file, int texture, int texcoord, const Json* info,
                        const std::string& where, TextureRef& ref) {
  auto image = texture_image(ctx, file, texture, where);
  if (!image) return image.error();
  ref.image = *image;
  ref.texcoord = texcoord;
  if (texture < 0) return {};
  auto sampler = texture_sampler(ctx, file, texture);
  if (!sampler) return sampler.error();
  ref.sampler = *sampler;
  if (info != nullptr) {
    if (auto ok = read_texture_transform(ctx, *info, where, ref); !ok) return ok;
  }
  if (ref.texcoord != 0 && ref.texcoord != 1) {
    return ctx.error(where, "texCoord " + std::to_string(ref.texcoord) +
                                " is not supported (the engine reads TEXCOORD_0 and TEXCOORD_1)");
  }
  return {};
}

Result<AlphaMode> alpha_mode(const Context& ctx, const std::string& mode, const std::string& where) {
  if (mode.empty() || mode == "OPAQUE") return AlphaMode::Opaque;
  if (mode == "MASK") return AlphaMode::Mask;
  if (mode == "BLEND") return AlphaMode::Blend;
  return ctx.error(where, "alphaMode '" + mode + "' is not OPAQUE, MASK or BLEND");
}

}  // namespace

// Long because it converts each material member by member in the spec's order (factors,
// extensions, texture slots, normal scale, alpha), each a check with its error, in one loop.
Result<std::vector<Material>> convert_materials(const Context& ctx, const ParsedFile& file) {
  std::vector<Material> out;
  const Json* json_materials = find_member(file.doc, "materials");
  for (std::size_t i = 0; i < file.model.materials.size(); ++i) {
    const tinygltf::Material& src = file.model.materials[i];
    const std::string where = "material " + std::to_string(i);
    Material m;
    m.name = src.name;
    m.double_sided = src.doubleSided;
    const auto& pbr = src.pbrMetallicRoughness;
    // §5.22: baseColorFactor has 4 components in [0, 1]; emissiveFactor 3 in [0, 1].
    if (pbr.baseColorFactor.size() != 4) return ctx.error(where, "baseColorFactor must have 4 components");
    for (int c = 0; c < 4; ++c) {
      auto v = unit_factor(ctx, pbr.baseColorFactor[static_cast<std::size_t>(c)], where, "baseColorFactor");
      if (!v) return v.error();
      m.base_color[c] = *v;
    }
    auto metallic = unit_factor(ctx, pbr.metallicFactor, where, "metallicFactor");
    if (!metallic) return metallic.error();
    auto roughness = unit_factor(ctx, pbr.roughnessFactor, where, "roughnessFactor");
    if (!roughness) return roughness.error();
    m.metallic = *metallic;
    m.roughness = *roughness;
    if (src.emissiveFactor.size() != 3) return ctx.error(where, "emissiveFactor must have 3 components");
    for (int c = 0; c < 3; ++c) {
      auto v = unit_factor(ctx, src.emissiveFactor[static_cast<std::size_t>(c)], where, "emissiveFactor");
      if (!v) return v.error();
      m.emissive[c] = *v;
    }
    if (json_materials != nullptr && i < json_materials->size()) {
      const Json* exts = find_member((*json_materials)[i], "extensions");
      if (auto ok = read_specular_extension(ctx, exts, where, m); !ok) return ok.error();
      // KHR_materials_emissive_strength: emissiveStrength >= 0 multiplies emissiveFactor.
      const Json* strength_ext = exts != nullptr ? find_member(*exts, "KHR_materials_emissive_strength") : nullptr;
      if (strength_ext != nullptr) {
        auto strength =
            number_member(ctx, *strength_ext, "emissiveStrength", 1.0, where + " KHR_materials_emissive_strength");
        if (!strength) return strength.error();
        // Finite as a double can overflow as a float once it multiplies emissiveFactor.
        if (!std::isfinite(*strength) || *strength < 0.0 || *strength > 1e15) {
          return ctx.error(where, "emissiveStrength must be a finite number in [0, 1e15]");
        }
        m.emissive *= static_cast<float>(*strength);
      }
    }
    const Json* json_material =
        json_materials != nullptr && i < json_materials->size() ? &(*json_materials)[i] : nullptr;
    const Json* json_pbr = json_material != nullptr ? find_member(*json_material, "pbrMetallicRoughness") : nullptr;
    const auto info = [](const Json* parent, const char* key) {
      return parent != nullptr ? find_member(*parent, key) : nullptr;
    };
    struct Slot {
      int index;
      int texcoord;
      const Json* info;
      TextureRef* target;
      const char* name;
    };
    const Slot slots[] = {
        {pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, info(json_pbr, "baseColorTexture"),
         &m.base_color_texture, "baseColorTexture"},
        {pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
         info(json_pbr, "metallicRoughnessTexture"), &m.metallic_roughness_texture, "metallicRoughnessTexture"},
        {src.normalTexture.index, src.normalTexture.texCoord, info(json_material, "normalTexture"), &m.normal_texture,
         "normalTexture"},
        {src.emissiveTexture.index, src.emissiveTexture.texCoord, info(json_material, "emissiveTexture"),
         &m.emissive_texture, "emissiveTexture"}};
    // The engine does not use occlusion, but a dangling reference is still a broken file.
    if (src.occlusionTexture.index >= 0 &&
        static_cast<std::size_t>(src.occlusionTexture.index) >= file.model.textures.size()) {
      return ctx.error(where + " occlusionTexture",
                       "texture " + std::to_string(src.occlusionTexture.index) + " is out of range");
    }
    const std::string named = where + (src.name.empty() ? "" : " '" + src.name + "'");
    for (const Slot& slot : slots) {
      if (auto ok =
              read_texture_ref(ctx, file, slot.index, slot.texcoord, slot.info, named + " " + slot.name, *slot.target);
          !ok)
        return ok.error();
    }
    // normalTexture.scale (§5.21.2): any finite number (negative flips the tangent-space XY).
    if (!std::isfinite(src.normalTexture.scale)) return ctx.error(named + " normalTexture", "scale must be finite");
    m.normal_scale = static_cast<float>(src.normalTexture.scale);
    auto mode = alpha_mode(ctx, src.alphaMode, named);
    if (!mode) return mode.error();
    m.alpha_mode = *mode;
    // alphaCutoff (§5.19.4): >= 0, default 0.5; only MASK reads it.
    if (!std::isfinite(src.alphaCutoff) || src.alphaCutoff < 0.0) {
      return ctx.error(named, "alphaCutoff must be a finite number >= 0, got " + std::to_string(src.alphaCutoff));
    }
    m.alpha_cutoff = static_cast<float>(src.alphaCutoff);
    out.push_back(std::move(m));
  }
  return out;
}

Status check_texcoord_sets(const Context& ctx, const SceneAsset& scene) {
  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& mesh = scene.meshes[mi];
    for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const Primitive& p = mesh.primitives[pi];
      if (p.material < 0 || static_cast<std::size_t>(p.material) >= scene.materials.size()) continue;
      const Material& m = scene.materials[static_cast<std::size_t>(p.material)];
      const std::pair<const TextureRef*, const char*> slots[] = {
          {&m.base_color_texture, "baseColorTexture"},
          {&m.metallic_roughness_texture, "metallicRoughnessTexture"},
          {&m.normal_texture, "normalTexture"},
          {&m.emissive_texture, "emissiveTexture"}};
      for (const auto& [ref, name] : slots) {
        if (!ref->present()) continue;
        const bool has = ref->texcoord == 0 ? !p.uv0.empty() : !p.uv1.empty();
        if (has) continue;
        return ctx.error("mesh " + std::to_string(mi) + (mesh.name.empty() ? "" : " '" + mesh.name + "'") +
                             " primitive " + std::to_string(pi),
                         "its material " + std::to_string(p.material) + (m.name.empty() ? "" : " '" + m.name + "'") +
                             " samples " + name + " with TEXCOORD_" + std::to_string(ref->texcoord) +
                             ", which the primitive does not have");
      }
    }
  }
  return {};
}

}  // namespace engine::gltf_load
