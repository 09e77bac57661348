#include <gi/baked_lighting.h>
#include <gi/light_atlas_lighting.h>
#include <gi/prm_lighting.h>

#include "bake/manifest.h"

namespace gi {

engine::Result<std::unique_ptr<engine::IndirectLightProvider>> load_baked_lighting(const std::filesystem::path& bundle_dir,
                                                                                    engine::Scene& scene) {
  auto manifest = read_manifest(bundle_dir);
  if (!manifest) return manifest.error();
  if (manifest->methods.contains("prm")) {
    auto prm = PrmLighting::load(bundle_dir, scene);
    if (!prm) return prm.error();
    return std::unique_ptr<engine::IndirectLightProvider>(std::move(prm).value());
  }
  if (manifest->methods.contains("light_atlas")) {
    auto atlas = LightAtlasLighting::load(bundle_dir, scene);
    if (!atlas) return atlas.error();
    return std::unique_ptr<engine::IndirectLightProvider>(std::move(atlas).value());
  }
  return engine::Error{(bundle_dir / "manifest.json").string(), "methods",
                       "the bundle holds neither a light atlas nor a PRM"};
}

}  // namespace gi
