#pragma once
// The checksummed binary container of bake files, and the atomic file write under it.
//   gi::write_blob(dir / "light_atlas_vpls.bin", gi::BlobMagic{"GIVPLSET"}, 1, payload);
//   engine::Result<std::vector<std::byte>> payload = gi::read_blob(path, gi::BlobMagic{"GIVPLSET"}, 1);
//
// Layout (little-endian, 28-byte header, then the payload):
//   offset  0  char[8]   magic      what the file holds ("GIVPLSET"...)
//   offset  8  uint32    version    of the payload layout, per magic
//   offset 12  uint64    size       payload bytes; the file is exactly 28 + size bytes
//   offset 20  uint64    checksum   XXH3-64 of the payload bytes (gi::ContentHash)
//   offset 28  payload
// XXH3-64 detects truncation, bit flips and changed content; it is not cryptographic.

#include <engine/result.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

namespace gi {

/// Exactly 8 characters naming a bake file's content.
struct BlobMagic {
  std::array<char, 8> chars{};
  /// From an 8-character literal (the terminating NUL is not stored).
  consteval BlobMagic(const char (&s)[9]) {  // NOLINT(google-explicit-constructor)
    for (std::size_t i = 0; i < 8; ++i) chars[i] = s[i];
  }
  std::string_view view() const { return {chars.data(), chars.size()}; }
};

inline constexpr std::size_t kBlobHeaderBytes = 28;

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed,
/// then renamed over `path`. On any failure the temporary file is removed, an existing
/// `path` is untouched and the error names `path`. The parent directory must exist.
engine::Status write_file_atomic(const std::filesystem::path& path, std::span<const std::byte> bytes);

/// The largest file read_file_bytes reads (1 GiB; a demo-level bundle at the high preset
/// is about 15 MB in all): a damaged or hostile file claiming terabytes is refused before
/// anything is allocated.
inline constexpr std::uint64_t kMaxBakeFileBytes = std::uint64_t{1} << 30;
/// The largest stream a bake file may decompress to (PRM panes, BRF coefficients,
/// antiradiance links): 4 GiB, checked against the frame's recorded size before allocating,
/// so a small crafted file cannot ask for more memory than any real bake uses.
inline constexpr std::uint64_t kMaxDecompressedBytes = std::uint64_t{4} << 30;

/// Reads a whole file. Error (naming it) when it is missing, unreadable or larger than
/// kMaxBakeFileBytes.
engine::Result<std::vector<std::byte>> read_file_bytes(const std::filesystem::path& path);

/// XXH3-64 (gi::ContentHash) of a whole file as 16 hex digits: what a manifest records
/// for each file it references. Error (naming it) when it cannot be read.
engine::Result<std::string> file_checksum(const std::filesystem::path& path);

/// Error naming `path` unless its file_checksum equals `expected` (the manifest's).
engine::Status check_file_checksum(const std::filesystem::path& path, const std::string& expected);

/// Header + payload, written atomically.
engine::Status write_blob(const std::filesystem::path& path, BlobMagic magic, std::uint32_t version,
                          std::span<const std::byte> payload);

/// The payload of a blob file. Errors name the file (Error::file) and say which check
/// failed: missing file, truncated header, wrong magic, wrong version, size mismatch
/// (truncated or trailing bytes), checksum mismatch.
engine::Result<std::vector<std::byte>> read_blob(const std::filesystem::path& path, BlobMagic magic,
                                                 std::uint32_t version);

}  // namespace gi
