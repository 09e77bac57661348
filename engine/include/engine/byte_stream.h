#pragma once
// Little-endian packing of plain values and arrays into a byte payload, and bounds-checked
// reading back: the one byte I/O of every binary file (bake bundles, recorded sessions).
// The host is little-endian (static_assert), so values are copied as they are.
//   engine::ByteWriter w; w.put(std::uint32_t{7}); w.put_array(std::span<const glm::vec3>(positions));
//   engine::ByteReader r(w.bytes()); std::uint32_t v = 0; if (!r.get(v)) { /* truncated */ }
// Name the type when the argument's is not the field's: w.put<std::uint32_t>(count).

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>
#include <glm/glm.hpp>

namespace engine {

static_assert(std::endian::native == std::endian::little, "binary files are little-endian; add byte swapping");

static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::vec4) == 16, "GLM vectors must be unpadded floats");

/// A value with a fixed byte layout: arithmetic types and GLM float vectors (no padding).
template <class T>
inline constexpr bool kPackable = std::is_arithmetic_v<T> || std::is_same_v<T, glm::vec2> ||
                                  std::is_same_v<T, glm::vec3> || std::is_same_v<T, glm::vec4>;

class ByteWriter {
 public:
  /// Writes into its own buffer (bytes(), take()).
  ByteWriter() : out_(&own_) {}
  /// Appends to `out`, which must outlive the writer.
  explicit ByteWriter(std::vector<std::byte>& out) : out_(&out) {}
  ByteWriter(const ByteWriter&) = delete;
  ByteWriter& operator=(const ByteWriter&) = delete;

  template <class T>
  void put(const T& v) {
    static_assert(kPackable<T>, "pack fields one by one");
    append(&v, sizeof(T));
  }
  /// uint64 element count, then the elements.
  template <class T>
  void put_array(std::span<const T> values) {
    static_assert(kPackable<T>, "pack fields one by one");
    put(static_cast<std::uint64_t>(values.size()));
    append(values.data(), values.size_bytes());
  }
  template <class T>
  void put_array(const std::vector<T>& values) {
    put_array(std::span<const T>(values));
  }
  /// uint64 length, then the characters.
  void put_string(const std::string& s) {
    put(static_cast<std::uint64_t>(s.size()));
    append(s.data(), s.size());
  }
  /// Raw bytes, no count (a magic, a fixed-length field).
  void put_bytes(const void* data, std::size_t n) { append(data, n); }
  std::span<const std::byte> bytes() const { return *out_; }
  std::vector<std::byte> take() { return std::move(*out_); }

 private:
  void append(const void* data, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = out_->size();
    out_->resize(at + n);
    std::memcpy(out_->data() + at, data, n);
  }
  std::vector<std::byte> own_;
  std::vector<std::byte>* out_;
};

/// Reads what ByteWriter wrote. Every getter returns false (and leaves the output alone)
/// when the payload is too short; counts are checked against the bytes left before
/// allocating, so a corrupt count cannot ask for gigabytes.
class ByteReader {
 public:
  explicit ByteReader(std::span<const std::byte> bytes) : bytes_(bytes) {}

  template <class T>
  bool get(T& v) {
    static_assert(kPackable<T>, "unpack fields one by one");
    if (remaining() < sizeof(T)) return false;
    std::memcpy(&v, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return true;
  }
  template <class T>
  bool get_array(std::vector<T>& out) {
    static_assert(kPackable<T>, "unpack fields one by one");
    std::uint64_t n = 0;
    if (!get(n) || n > remaining() / sizeof(T)) return false;
    out.resize(static_cast<std::size_t>(n));
    if (n > 0) std::memcpy(out.data(), bytes_.data() + offset_, static_cast<std::size_t>(n) * sizeof(T));
    offset_ += static_cast<std::size_t>(n) * sizeof(T);
    return true;
  }
  /// `n` characters, no count (the count was read before).
  bool get_chars(std::string& out, std::size_t n) {
    if (n > remaining()) return false;
    out.assign(reinterpret_cast<const char*>(bytes_.data() + offset_), n);
    offset_ += n;
    return true;
  }
  bool get_string(std::string& out) {
    std::uint64_t n = 0;
    if (!get(n) || n > remaining()) return false;
    out.assign(reinterpret_cast<const char*>(bytes_.data() + offset_), static_cast<std::size_t>(n));
    offset_ += static_cast<std::size_t>(n);
    return true;
  }

  std::size_t offset() const { return offset_; }
  std::size_t remaining() const { return bytes_.size() - offset_; }

 private:
  std::span<const std::byte> bytes_;
  std::size_t offset_ = 0;
};

}  // namespace engine
