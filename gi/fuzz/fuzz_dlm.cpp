// Fuzz target: dlm.bin, the directional light maps (gi::read_dlm_file), payload re-sealed
// (fuzz_blob_support.h). Check: what reads is written again by gi::write_dlm_file and
// reads back.
#include "dlm/dlm_io.h"
#include "fuzz_blob_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_sealed_blob("dlm.bin", data, size);
  engine::Result<gi::DlmFile> file = gi::read_dlm_file(path);
  if (!file) {
    gi_fuzz::refused(file.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  gi_fuzz::check_rewrite(
      "dlm.bin", [&](const auto& p) { return gi::write_dlm_file(p, file->dlm, file->geometry_hash); },
      [](const auto& p) { return gi::read_dlm_file(p); });
  return 0;
}
