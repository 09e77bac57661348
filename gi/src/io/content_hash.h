#pragma once
// A 64-bit content hash for cache keys and file checksums: XXH3-64 (Debian's libxxhash),
// streamed. Not cryptographic: it detects truncation, bit flips and changed content, it
// does not resist deliberate collisions. Values are stable across runs and machines.
//   gi::ContentHash h;
//   h.add_bytes(data.data(), data.size()); std::string hex = h.hex();

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t by value: no allocation per hash
#include <xxhash.h>

namespace gi {

class ContentHash {
 public:
  ContentHash() { XXH3_64bits_reset(&state_); }
  /// Mixes `size` bytes into the hash.
  void add_bytes(const void* data, std::size_t size) {
    if (size > 0) XXH3_64bits_update(&state_, data, size);
  }
  /// Mixes a string, prefixed with its length so ("ab","c") and ("a","bc") differ.
  void add_string(std::string_view s) {
    add_value(static_cast<std::uint64_t>(s.size()));
    add_bytes(s.data(), s.size());
  }
  /// Mixes the bytes of a trivially copyable value without padding (ints, floats).
  template <class T>
  void add_value(const T& v) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>, "hash fields one by one, never padded structs");
    add_bytes(&v, sizeof(T));
  }
  template <class T>
  void add_values(std::span<const T> values) {
    add_value(static_cast<std::uint64_t>(values.size()));
    if constexpr (std::is_arithmetic_v<T>) {
      add_bytes(values.data(), values.size_bytes());  // same stream as value by value, in one call
    } else {
      for (const T& v : values) add_value(v);
    }
  }

  /// The hash of everything added so far (more may be added after).
  std::uint64_t value() const { return XXH3_64bits_digest(&state_); }
  /// value() as 16 lowercase hex digits.
  std::string hex() const {
    static constexpr char digits[] = "0123456789abcdef";
    const std::uint64_t v = value();
    std::string s(16, '0');
    for (int i = 0; i < 16; ++i) s[static_cast<std::size_t>(15 - i)] = digits[(v >> (4 * i)) & 0xfu];
    return s;
  }

 private:
  XXH3_state_t state_;
};

}  // namespace gi
