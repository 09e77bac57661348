// Materials and images of the glTF loader: metallic-roughness factors and textures
// (glTF 2.0 §3.9), emissive strength (KHR_materials_emissive_strength), images decoded to
// RGBA8 with stb_image. A missing or undecodable image is an error naming its URI: a game
// must not ship a broken texture silently (docs/scene-format.md).

#include <cmath>
#include <cstdio>

#include <stb_image.h>  // compiled in tinygltf_impl.cpp (STB_IMAGE_IMPLEMENTATION)

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
    state->failures[idx] = "image of " + std::to_string(w) + "x" + std::to_string(h) +
                           " pixels exceeds the limit of " + std::to_string(state->max_dimension);
    return true;
  }
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
    if (auto ok = image_status(ctx, file, static_cast<int>(i)); !ok) {
      // Only images that materials use must load (checked there); others are reported.
      std::fprintf(stderr, "warning: %s (unused by materials)\n", ok.error().to_string().c_str());
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
    return ctx.error("texture " + std::to_string(texture), "source image " + std::to_string(source) + " is out of range");
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
  if (!color->is_array() || color->size() != 3) return ctx.error(at, "specularColorFactor must be an array of 3 numbers");
  for (std::size_t c = 0; c < 3; ++c) {
    const Json& v = (*color)[c];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0.0 || v.get<double>() > 1e6) {
      return ctx.error(at, "specularColorFactor components must be finite numbers in [0, 1e6]");
    }
    m.specular_color_factor[static_cast<glm::length_t>(c)] = static_cast<float>(v.get<double>());
  }
  return {};
}

}  // namespace

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
        auto strength = number_member(ctx, *strength_ext, "emissiveStrength", 1.0,
                                      where + " KHR_materials_emissive_strength");
        if (!strength) return strength.error();
        // Finite as a double can overflow as a float once it multiplies emissiveFactor.
        if (!std::isfinite(*strength) || *strength < 0.0 || *strength > 1e15) {
          return ctx.error(where, "emissiveStrength must be a finite number in [0, 1e15]");
        }
        m.emissive *= static_cast<float>(*strength);
      }
    }
    struct Slot {
      int index;
      int texcoord;
      TextureRef* target;
      const char* name;
    };
    const Slot slots[] = {{pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, &m.base_color_texture, "baseColorTexture"},
                          {pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, &m.metallic_roughness_texture, "metallicRoughnessTexture"},
                          {src.normalTexture.index, src.normalTexture.texCoord, &m.normal_texture, "normalTexture"},
                          {src.emissiveTexture.index, src.emissiveTexture.texCoord, &m.emissive_texture, "emissiveTexture"}};
    // The engine does not use occlusion, but a dangling reference is still a broken file.
    if (src.occlusionTexture.index >= 0 && static_cast<std::size_t>(src.occlusionTexture.index) >= file.model.textures.size()) {
      return ctx.error(where + " occlusionTexture", "texture " + std::to_string(src.occlusionTexture.index) + " is out of range");
    }
    for (const Slot& slot : slots) {
      auto image = texture_image(ctx, file, slot.index, where + " " + slot.name);
      if (!image) return image.error();
      slot.target->image = *image;
      slot.target->texcoord = slot.texcoord;
    }
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace engine::gltf_load
