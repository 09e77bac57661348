#pragma once
// The methods GISystem runs, in load and frame order (system/method_runtime.h). Adding a
// method at run time: its adapter file (system/<key>_method.cpp, a MethodRuntime and its
// loader) and one row here; nothing else in the system changes.

#include <engine/result.h>
#include <gi/plan.h>

#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "system/method_runtime.h"

namespace gi {

struct MethodRuntimeEntry {
  EffectMethod method;  ///< Its key in the manifest and its name: gi/methods.h.
  /// Loads the method from the bundle: a runtime, none (a superseded method that only
  /// publishes its bake), or an error naming the file and the problem.
  engine::Result<std::unique_ptr<MethodRuntime>> (*load)(MethodLoad& load);
  /// The method whose runtime this one replaces when both are in the bundle (the PRM draws
  /// the light atlas's light under its panes).
  std::optional<EffectMethod> supersedes;
  /// Whether the method alone gives the static world or dynamic objects light (antiradiance
  /// only changes another method's atlas).
  bool stands_alone = true;
};

/// Whether the bundle's manifest holds `m`'s files.
bool in_manifest(const Manifest& manifest, EffectMethod m);

/// In load and frame order.
std::span<const MethodRuntimeEntry> method_runtimes();

// Each method's loader, in its adapter file.
engine::Result<std::unique_ptr<MethodRuntime>> load_light_atlas_method(MethodLoad& load);
engine::Result<std::unique_ptr<MethodRuntime>> load_prm_method(MethodLoad& load);
engine::Result<std::unique_ptr<MethodRuntime>> load_brf_method(MethodLoad& load);
engine::Result<std::unique_ptr<MethodRuntime>> load_dlm_method(MethodLoad& load);
engine::Result<std::unique_ptr<MethodRuntime>> load_antiradiance_method(MethodLoad& load);
engine::Result<std::unique_ptr<MethodRuntime>> load_reflection_probes_method(MethodLoad& load);

}  // namespace gi
