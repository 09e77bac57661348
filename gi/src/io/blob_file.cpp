#include "io/blob_file.h"

#include <engine/byte_stream.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>

#include "io/atomic_file.h"
#include "io/content_hash.h"

namespace gi {

namespace {

std::uint64_t payload_checksum(std::span<const std::byte> payload) {
  ContentHash h;
  h.add_bytes(payload.data(), payload.size());
  return h.value();
}

// Printable form of a magic read from a file (non-printable bytes as '?').
std::string printable(std::span<const std::byte> chars) {
  std::string s;
  for (std::byte b : chars) {
    const auto c = static_cast<unsigned char>(b);
    s += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
  }
  return s;
}

engine::Error blob_error(const std::filesystem::path& path, std::string location, std::string message) {
  return engine::Error{path.string(), std::move(location), std::move(message)};
}

}  // namespace

engine::Status write_file_atomic(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  return write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

engine::Result<std::vector<std::byte>> read_file_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return blob_error(path, "", "file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) return blob_error(path, "", "cannot open the file");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) return blob_error(path, "", "cannot read the file size");
  if (static_cast<std::uint64_t>(size) > kMaxBakeFileBytes)
    return blob_error(path, "",
                      std::to_string(size) + " bytes: larger than any bake file can be (at most " +
                          std::to_string(kMaxBakeFileBytes) + ")");
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) return blob_error(path, "", "read failed");
  return bytes;
}

engine::Status write_blob(const std::filesystem::path& path, BlobMagic magic, std::uint32_t version,
                          std::span<const std::byte> payload) {
  engine::ByteWriter w;
  for (char c : magic.chars) w.put(c);
  w.put(version);
  w.put(static_cast<std::uint64_t>(payload.size()));
  w.put(payload_checksum(payload));
  std::vector<std::byte> file = w.take();
  file.insert(file.end(), payload.begin(), payload.end());
  return write_file_atomic(path, file);
}

engine::Result<std::vector<std::byte>> read_blob(const std::filesystem::path& path, BlobMagic magic,
                                                 std::uint32_t version) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return bytes.error();
  const std::vector<std::byte>& file = bytes.value();
  if (file.size() < kBlobHeaderBytes) {
    return blob_error(path, "header",
                      "truncated header: " + std::to_string(file.size()) + " bytes, a " +
                          std::to_string(kBlobHeaderBytes) + "-byte header expected");
  }
  const std::span<const std::byte> head(file.data(), kBlobHeaderBytes);
  if (std::memcmp(head.data(), magic.chars.data(), 8) != 0) {
    return blob_error(path, "header",
                      "wrong magic \"" + printable(head.first(8)) + "\", expected \"" + std::string(magic.view()) +
                          "\" (not this kind of bake file)");
  }
  engine::ByteReader r(head.subspan(8));
  std::uint32_t file_version = 0;
  std::uint64_t size = 0, checksum = 0;
  r.get(file_version);
  r.get(size);
  r.get(checksum);
  if (file_version != version) {
    return blob_error(path, "header",
                      "unsupported version " + std::to_string(file_version) + ", this build reads " +
                          std::to_string(version) + " (re-bake)");
  }
  const std::uint64_t actual = file.size() - kBlobHeaderBytes;
  if (size != actual) {
    return blob_error(path, "header",
                      "size mismatch: the header says " + std::to_string(size) + " payload bytes, the file holds " +
                          std::to_string(actual) + (actual < size ? " (truncated)" : " (trailing bytes)"));
  }
  std::vector<std::byte> payload(file.begin() + static_cast<std::ptrdiff_t>(kBlobHeaderBytes), file.end());
  if (payload_checksum(payload) != checksum) {
    return blob_error(path, "payload", "checksum mismatch: the payload is corrupt");
  }
  return payload;
}

engine::Result<std::string> file_checksum(const std::filesystem::path& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return bytes.error();
  ContentHash h;
  h.add_bytes(bytes->data(), bytes->size());
  return h.hex();
}

engine::Status check_file_checksum(const std::filesystem::path& path, const std::string& expected) {
  auto actual = file_checksum(path);
  if (!actual) return actual.error();
  if (*actual != expected)
    return engine::Error{path.string(), "",
                         "checksum mismatch: the manifest expects XXH3-64 " + expected + ", the file has " + *actual +
                             " (corrupt, or from another bake; re-bake)"};
  return {};
}

}  // namespace gi
