// Fuzz target: prm_panes.bin with its zstd stream (gi::read_prm_panes), payload re-sealed
// (fuzz_blob_support.h). Check: what reads is written again by gi::write_prm_panes and
// reads back.
#include "fuzz_blob_support.h"
#include "prm/prm_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_sealed_blob("prm_panes.bin", data, size);
  engine::Result<gi::PrmPaneFile> file = gi::read_prm_panes(path);
  if (!file) {
    gi_fuzz::refused(file.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  gi_fuzz::check_rewrite(
      "prm_panes.bin", [&](const auto& p) { return gi::write_prm_panes(p, file->prm, file->geometry_hash); },
      [](const auto& p) { return gi::read_prm_panes(p); });
  return 0;
}
