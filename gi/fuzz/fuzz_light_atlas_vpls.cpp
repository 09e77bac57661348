// Fuzz target: light_atlas_vpls.bin (gi::read_light_atlas_vpls), payload re-sealed
// (fuzz_blob_support.h). Check: what reads is written again by gi::write_light_atlas_vpls
// and reads back.
#include "fuzz_blob_support.h"
#include "light_atlas/light_atlas_vpl_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = gi_fuzz::write_sealed_blob("light_atlas_vpls.bin", data, size);
  engine::Result<gi::LightAtlasVplFile> file = gi::read_light_atlas_vpls(path);
  if (!file) {
    gi_fuzz::refused(file.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  gi::LightAtlasBake bake;
  bake.settings = file->settings;
  bake.vpls = file->vpls;
  bake.vpl_power = file->vpl_power;
  gi_fuzz::check_rewrite(
      "light_atlas_vpls.bin", [&](const auto& p) { return gi::write_light_atlas_vpls(p, bake, file->geometry_hash); },
      [](const auto& p) { return gi::read_light_atlas_vpls(p); });
  return 0;
}
