#include <gi/baked_lighting.h>
#include <gi/gi_system.h>

namespace gi {

engine::Result<std::unique_ptr<engine::IndirectLightProvider>> load_baked_lighting(const std::filesystem::path& bundle_dir,
                                                                                    engine::Scene& scene) {
  auto system = GISystem::load(bundle_dir, scene);
  if (!system) return system.error();
  return std::unique_ptr<engine::IndirectLightProvider>(std::move(system).value());
}

}  // namespace gi
