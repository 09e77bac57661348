// Fuzz target: a bundle's manifest.json (gi::read_manifest). Check: a manifest that reads,
// written with gi::write_manifest, reads back with the same fields.
#include "bundle/manifest.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  gi_fuzz::write_scratch(gi::kManifestFileName, data, size);
  engine::Result<gi::Manifest> m = gi::read_manifest(gi_fuzz::scratch_dir());
  if (!m) {
    gi_fuzz::refused(m.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  if (engine::Status s = gi::write_manifest(gi_fuzz::scratch_dir(), *m); !s)
    gi_fuzz::fail("write_manifest refused what read_manifest accepted: " + s.error().to_string());
  engine::Result<gi::Manifest> back = gi::read_manifest(gi_fuzz::scratch_dir());
  if (!back) gi_fuzz::fail("the re-written manifest does not read: " + back.error().to_string());
  if (back->format_version != m->format_version || back->geometry_hash != m->geometry_hash || back->scene != m->scene ||
      back->methods != m->methods || back->plan != m->plan)
    gi_fuzz::fail("the re-written manifest reads back other fields");
  return 0;
}
