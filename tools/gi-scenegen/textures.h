#pragma once
// Procedural textures of the generated scenes, made here from fixed seeds (no third-party
// images): brick, wooden planks, a woven tartan and a wire mesh with alpha cut-outs. Each
// covers 1 m x 1 m of a surface (TEXCOORD_0 is in metres, see scene_builder.h) and tiles
// seamlessly with a REPEAT sampler. Base colours are sRGB-encoded 8-bit RGBA; the patterns
// use integer hashes and float arithmetic only (no libm calls), so every platform writes
// the same bytes.
//   int bricks = builder.image(scenegen::brick_texture());
//   glm::vec3 albedo = scenegen::mean_linear_rgb(scenegen::brick_texture());

#include <engine/scene_asset.h>

#include <cstdint>
#include <glm/glm.hpp>

namespace scenegen {

/// Metres of surface one texture covers along u and v (1 repeat per metre).
inline constexpr float kTextureTileM = 1.0f;

/// 256 x 256: red and orange bricks (25 x 6.25 cm, 16 courses) in running bond with grey
/// mortar joints; opaque. Mean linear albedo about (0.43, 0.15, 0.09).
engine::Image brick_texture();
/// 256 x 256: four 25 cm planks along u, two boards per plank with butt joints, grain
/// rings and knots; opaque.
engine::Image wood_planks_texture();
/// 128 x 128: a 2/2 twill weave of 4-pixel threads in a navy / green tartan with cream and
/// red lines; opaque.
engine::Image tartan_fabric_texture();
/// 256 x 256: a wire-mesh grille (16 diamonds per metre, ~14 mm wires that alternate over
/// and under at the crossings), alpha 255 on the wire and 0 in the holes (about half of
/// the texels; the hole texels carry the wire's colour so filtering does not darken edges).
engine::Image wire_mesh_texture();

/// Linear value of an sRGB-encoded 8-bit channel (IEC 61966-2-1).
float srgb8_to_linear(std::uint8_t c);
/// The sRGB-encoded 8-bit code nearest to the linear value `v` (clamped to [0, 1]).
std::uint8_t linear_to_srgb8(float v);

/// Mean linear RGB of an sRGB-encoded image over the texels with alpha >= `min_alpha`
/// (0: all texels).
glm::vec3 mean_linear_rgb(const engine::Image& image, std::uint8_t min_alpha = 0);
/// Fraction of the texels whose alpha is below `cutoff` x 255 (cut out under alphaMode MASK).
float transparent_fraction(const engine::Image& image, float cutoff = 0.5f);

}  // namespace scenegen
