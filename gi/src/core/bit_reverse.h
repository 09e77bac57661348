#pragma once
// The bits of a 32-bit integer in reverse order: Van der Corput's radical inverse in base 2
// is reverse_bits(i) x 2^-32 (Hammersley points in the light atlas's gather and the
// reflection probes' prefilter; each keeps as many of the bits as its float needs).
//   const float u = static_cast<float>(gi::reverse_bits(i) >> 8) * 0x1p-24f;

#include <cstdint>

namespace gi {

inline std::uint32_t reverse_bits(std::uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
  i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
  i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
  return i;
}

}  // namespace gi
