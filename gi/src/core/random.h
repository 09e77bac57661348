#pragma once
// PCG32 random streams (O'Neill 2014, "PCG: a family of simple fast space-efficient
// statistically good algorithms"): 64-bit LCG state, XSH-RR output. Every stream is seeded
// from (global seed, work-item id), so results do not depend on which thread ran the item.
//   gi::Pcg32 rng = gi::Pcg32::for_item(settings.seed, texel_index);
//   float u = rng.next_float();
// Never two draws in the arguments of one call or constructor: their order is unspecified
// (GCC evaluated them right to left, clang left to right), so a bake, its reference and the
// golden frames depended on the compiler. Draw into named variables first; the sites that
// had two keep GCC's order (the second argument drawn first), so GCC's bakes are unchanged.

#include <cstdint>

namespace gi {

class Pcg32 {
 public:
  /// A stream for one work item: the item id selects the LCG increment (the stream) and is
  /// mixed into the state, so neighbouring items are decorrelated.
  static Pcg32 for_item(std::uint64_t global_seed, std::uint64_t item_id) {
    return Pcg32(splitmix64(global_seed ^ splitmix64(item_id)), item_id);
  }

  Pcg32(std::uint64_t seed, std::uint64_t stream) : inc_((stream << 1u) | 1u) {
    next_u32();
    state_ += seed;
    next_u32();
  }

  std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  /// Uniform in [0, 1): 24 random mantissa bits, never 1.
  float next_float() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }

  /// splitmix64 finalizer, used to derive seeds.
  static constexpr std::uint64_t splitmix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_;
};

}  // namespace gi
