// Fuzz target: <method>_layout.bin (gi::read_atlas_layout_file, the atlas layout a bake
// writes and a load reads), payload re-sealed (fuzz_blob_support.h). Check: what reads is
// written again by gi::write_atlas_layout_file and reads back.
#include "bundle/atlas_layout_file.h"
#include "fuzz_blob_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_sealed_blob("layout.bin", data, size);
  engine::Result<gi::AtlasLayoutFile> file = gi::read_atlas_layout_file(path);
  if (!file) {
    gi_fuzz::refused(file.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  gi_fuzz::check_rewrite(
      "layout.bin", [&](const auto& p) { return gi::write_atlas_layout_file(p, file->layout, file->geometry_hash); },
      [](const auto& p) { return gi::read_atlas_layout_file(p); });
  return 0;
}
