// Fuzz target: brf_<name>.bin with its zstd stream and glossy separation
// (gi::read_brf_mesh), payload re-sealed (fuzz_blob_support.h). Check: what reads is
// written again by gi::write_brf_mesh and reads back.
#include "brf/brf_io.h"
#include "fuzz_blob_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_sealed_blob("brf_crate.bin", data, size);
  engine::Result<gi::BrfMeshBake> bake = gi::read_brf_mesh(path);
  if (!bake) {
    gi_fuzz::refused(bake.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  gi_fuzz::check_rewrite(
      "brf_crate.bin", [&](const auto& p) { return gi::write_brf_mesh(p, *bake); },
      [](const auto& p) { return gi::read_brf_mesh(p); });
  return 0;
}
