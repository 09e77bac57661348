#pragma once
// One call for a game that only needs the renderer hook: gi::GISystem::load (gi_system.h)
// as a plain engine::IndirectLightProvider. Use GISystem directly for its stats.
//   auto gi = gi::load_baked_lighting("level.gibake", scene);   // before Renderer::create
//   if (!gi) { std::cerr << gi.error().to_string() << '\n'; return 1; }
//   renderer->set_indirect_light(gi.value().get());

#include <filesystem>
#include <memory>

#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>

namespace gi {

/// Loads the bundle's baked lighting for `scene` (which gains TEXCOORD_1; the registry must
/// outlive the provider). Errors: those of GISystem::load.
engine::Result<std::unique_ptr<engine::IndirectLightProvider>> load_baked_lighting(const std::filesystem::path& bundle_dir,
                                                                                    engine::Scene& scene);

}  // namespace gi
