#pragma once
// For the fuzz targets of the bake files in the checksummed container (io/blob_file.h):
// every input is "re-sealed" before it is written, its header's size and XXH3-64 fields
// set to those of the bytes after the header, so the mutations reach the payload parser
// instead of all stopping at the checksum (the container's own checks are fuzzed raw by
// fuzz_blob.cpp). Magic and version stay as the input has them.
//   std::filesystem::path p = gi_fuzz::write_sealed_blob("prm_panes.bin", data, size);

#include <cstring>
#include <vector>

#include "fuzz_support.h"
#include "io/blob_file.h"
#include "io/content_hash.h"

namespace gi_fuzz {

inline std::filesystem::path write_sealed_blob(const std::string& name, const std::uint8_t* data, std::size_t size) {
  if (size < gi::kBlobHeaderBytes) return write_scratch(name, data, size);
  std::vector<std::uint8_t> bytes(data, data + size);
  const std::uint64_t payload = size - gi::kBlobHeaderBytes;
  gi::ContentHash h;
  h.add_bytes(bytes.data() + gi::kBlobHeaderBytes, payload);
  const std::uint64_t checksum = h.value();
  std::memcpy(bytes.data() + 12, &payload, sizeof payload);  // little-endian hosts only, as the format
  std::memcpy(bytes.data() + 20, &checksum, sizeof checksum);
  return write_scratch(name, bytes.data(), bytes.size());
}

/// What a reader accepted, its writer must accept and the reader read back.
template <class Write, class Read>
void check_rewrite(const char* what, Write write, Read read) {
  const std::filesystem::path again = scratch_dir() / "again.bin";
  if (engine::Status s = write(again); !s)
    fail(std::string(what) + ": the writer refused what the reader accepted: " + s.error().to_string());
  auto back = read(again);
  if (!back) fail(std::string(what) + ": the re-written file does not read: " + back.error().to_string());
}

}  // namespace gi_fuzz
