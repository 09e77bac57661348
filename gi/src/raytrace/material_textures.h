#pragma once
// Material textures as every baker and the path tracer read them (docs/materials-in-bakes.md):
// one mip chain per (image, encoding), box-filtered in linear space (sRGB colour is decoded
// before it is averaged), sampled bilinearly between the two mip levels around the level a
// lookup's footprint asks for (trilinear), with the glTF sampler's wrap modes and the
// texture's KHR_texture_transform. Plain data: tests build it by hand.
//   gi::TextureMips mips = gi::build_texture_mips(image, /*srgb=*/true);
//   glm::vec4 rgba = gi::sample_texture(mips, sampler, uv, gi::mip_level(mips, uv_footprint));

#include <engine/scene_asset.h>
#include <gi/bake_input.h>

#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// A mip chain of linear RGBA values in [0, 1].
struct TextureMips {
  struct Level {
    int width = 0;
    int height = 0;
    std::vector<glm::vec4> texels;  ///< Row-major, rows top to bottom as in the image.
  };
  std::vector<Level> levels;  ///< 0: full size; each next one half the size (at least 1), down to 1 x 1.
};

/// The sRGB transfer function's inverse (IEC 61966-2-1) of an 8-bit value.
float srgb_to_linear(std::uint8_t v);

/// Decodes `image` (RGB through srgb_to_linear when `srgb`; alpha always linear) and
/// box-filters it down to 1 x 1: each texel of level k+1 is the mean of the texels of level
/// k under its box (2 x 2 on even sizes; on an odd axis the box spans n / m source texels,
/// each weighted by its overlap), so every level keeps the image's mean.
/// Precondition: a valid image (width, height >= 1, width x height x 4 bytes).
TextureMips build_texture_mips(const BakeImage& image, bool srgb);

/// The mip level (fractional, clamped to the chain) whose texel spans `uv_footprint`, a
/// lookup's footprint width in UV units (1 = the whole texture): log2(footprint x size).
float mip_level(const TextureMips& mips, float uv_footprint);

/// The texture at `uv` (after any transform): bilinear within the two levels around `level`,
/// linear between them; wrap modes from `sampler` (a sampler without mipmaps reads level 0).
glm::vec4 sample_texture(const TextureMips& mips, const engine::TextureSampler& sampler, glm::vec2 uv, float level);

/// A material's texture in the path tracer's scene: the mip chain (index into
/// ReferenceScene::textures, -1: none), the UV set it reads (0 or 1), sampler and transform.
struct MaterialTexture {
  int mips = -1;
  int texcoord = 0;
  engine::TextureSampler sampler;
  engine::TextureTransform transform;
  bool present() const { return mips >= 0; }
};

/// Where a texture is read on a triangle: the UV at the point (before the transform) and
/// the footprint's width in UV units (0: the finest level).
glm::vec4 sample_material_texture(const std::vector<TextureMips>& textures, const MaterialTexture& t, glm::vec2 uv,
                                  float uv_footprint);

/// Texel coordinate i of an axis of n texels under a glTF wrap mode (also the alpha cut-outs').
int wrap_texel(int i, int n, engine::TextureWrap mode);

}  // namespace gi
