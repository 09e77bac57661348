// Fuzz target: the checksummed container of every bake file (gi::read_blob, io/blob_file.h),
// raw: header, magic, version, size and checksum checks. Check: a payload that reads,
// written again with gi::write_blob, gives exactly the input bytes. The container is read as
// dlm.bin's (its magic and current version, dlm/dlm_io.h), the files the seeds are: a version
// written here by hand would leave every seed refused after a format bump.
#include <cstring>

#include "dlm/dlm_io.h"
#include "fuzz_support.h"
#include "io/blob_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr gi::BlobMagic kMagic = gi::kDlmMagic;
  const std::filesystem::path path = gi_fuzz::write_scratch("blob.bin", data, size);
  engine::Result<std::vector<std::byte>> payload = gi::read_blob(path, kMagic, gi::kDlmVersion);
  if (!payload) {
    if (payload.error().file.empty()) gi_fuzz::fail("read_blob's error does not name the file");
    gi_fuzz::refused(payload.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  const std::filesystem::path again = gi_fuzz::scratch_dir() / "again.bin";
  if (engine::Status s = gi::write_blob(again, kMagic, gi::kDlmVersion, *payload); !s)
    gi_fuzz::fail(s.error().to_string());
  auto bytes = gi::read_file_bytes(again);
  if (!bytes || bytes->size() != size || std::memcmp(bytes->data(), data, size) != 0)
    gi_fuzz::fail("write_blob of the payload read does not give the input back");
  return 0;
}
