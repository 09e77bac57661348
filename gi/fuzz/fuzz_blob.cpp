// Fuzz target: the checksummed container of every bake file (gi::read_blob, io/blob_file.h),
// raw: header, magic, version, size and checksum checks. Check: a payload that reads,
// written again with gi::write_blob, gives exactly the input bytes.
#include <cstring>

#include "fuzz_support.h"
#include "io/blob_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr gi::BlobMagic kMagic{"GIDLMAPS"};
  const std::filesystem::path path = gi_fuzz::write_scratch("blob.bin", data, size);
  engine::Result<std::vector<std::byte>> payload = gi::read_blob(path, kMagic, 1);
  if (!payload) {
    if (payload.error().file.empty()) gi_fuzz::fail("read_blob's error does not name the file");
    gi_fuzz::refused(payload.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  const std::filesystem::path again = gi_fuzz::scratch_dir() / "again.bin";
  if (engine::Status s = gi::write_blob(again, kMagic, 1, *payload); !s) gi_fuzz::fail(s.error().to_string());
  auto bytes = gi::read_file_bytes(again);
  if (!bytes || bytes->size() != size || std::memcmp(bytes->data(), data, size) != 0)
    gi_fuzz::fail("write_blob of the payload read does not give the input back");
  return 0;
}
