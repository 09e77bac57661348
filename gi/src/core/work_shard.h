#pragma once
// Which items of a parallel bake loop one shard of a distributed bake computes
// (docs/distributed-bake.md): items are cut into blocks of kBlockItems consecutive indices
// and block b belongs to shard b mod count, so every shard gets a share of every part of
// the atlas (cheap and expensive regions alike) and the split depends on nothing but the
// item count. A whole bake is the shard 0 of 1.
//   gi::WorkShard shard{.index = 2, .count = 7};
//   for (std::size_t i = 0; i < n; ++i) if (shard.owns(i)) out[i] = work(i);

#include <cstddef>
#include <cstdint>
#include <vector>

namespace gi {

struct WorkShard {
  static constexpr std::size_t kBlockItems = 64;
  std::uint32_t index = 0;
  std::uint32_t count = 1;

  bool whole() const { return count <= 1; }
  bool owns(std::size_t item) const { return whole() || (item / kBlockItems) % count == index; }
  /// The items of [0, n) this shard owns, ascending.
  std::vector<std::size_t> items(std::size_t n) const {
    std::vector<std::size_t> out;
    out.reserve(whole() ? n : n / count + kBlockItems);
    for (std::size_t i = 0; i < n; ++i)
      if (owns(i)) out.push_back(i);
    return out;
  }
};

}  // namespace gi
