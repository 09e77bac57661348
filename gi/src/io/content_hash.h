#pragma once
// A 64-bit FNV-1a hash for cache keys and file checksums (not cryptographic: it detects
// truncation, bit flips and changed content, it does not resist deliberate collisions).
//   gi::ContentHash h;
//   h.add_bytes(data.data(), data.size()); std::string hex = h.hex();

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

namespace gi {

class ContentHash {
 public:
  /// Mixes `size` bytes into the hash.
  void add_bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      state_ ^= p[i];
      state_ *= 0x100000001b3ull;
    }
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
    for (const T& v : values) add_value(v);
  }

  std::uint64_t value() const { return state_; }
  /// 16 lowercase hex digits.
  std::string hex() const {
    static constexpr char digits[] = "0123456789abcdef";
    std::string s(16, '0');
    for (int i = 0; i < 16; ++i) s[static_cast<std::size_t>(15 - i)] = digits[(state_ >> (4 * i)) & 0xfu];
    return s;
  }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

}  // namespace gi
