#pragma once
// Stratified sample points shared by the texel gather's steps (texel_gather.h) and its
// direct light (texel_direct.h).
//   const glm::vec2 u = gi::hammersley(s, samples, shift);

#include <cstdint>
#include <glm/glm.hpp>

#include "core/bit_reverse.h"

namespace gi {

// Van der Corput in base 2: the bits of i mirrored about the binary point (24 bits kept).
inline float radical_inverse(std::uint32_t i) { return static_cast<float>(reverse_bits(i) >> 8) * 0x1p-24f; }

// Point i of an n-point Hammersley set, shifted on the torus (Cranley-Patterson rotation):
// stratified in both dimensions for any n, decorrelated between texels by the shift.
inline glm::vec2 hammersley(std::uint32_t i, std::uint32_t n, glm::vec2 shift) {
  const glm::vec2 u((static_cast<float>(i) + 0.5f) / static_cast<float>(n), radical_inverse(i));
  glm::vec2 s = u + shift;
  s -= glm::floor(s);
  return glm::min(s, glm::vec2(0x1.fffffep-1f));
}

}  // namespace gi
