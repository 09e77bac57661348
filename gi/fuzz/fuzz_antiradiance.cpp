// Fuzz target: antiradiance.bin with its zstd link stream (gi::read_antiradiance), payload
// re-sealed (fuzz_blob_support.h). Check: what reads is written again by
// gi::write_antiradiance and reads back.
#include "antiradiance/antiradiance_io.h"
#include "fuzz_blob_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_sealed_blob("antiradiance.bin", data, size);
  engine::Result<gi::AntiradianceFile> file = gi::read_antiradiance(path);
  if (!file) {
    gi_fuzz::refused(file.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  gi_fuzz::check_rewrite(
      "antiradiance.bin", [&](const auto& p) { return gi::write_antiradiance(p, file->bake, file->geometry_hash); },
      [](const auto& p) { return gi::read_antiradiance(p); });
  return 0;
}
