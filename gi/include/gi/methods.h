#pragma once
// The GI methods and their one name each (issue 34): the key is what gi-bake --methods, the
// bundle's manifest, the plan's output, the sweep registry and the docs spell; the name is
// what labels, logs and GISystem::Stats::disabled say. Every place takes them from this
// table, so a method is never "atlas" in one file and "light_atlas" in the next.
//   for (const gi::MethodDescriptor& m : gi::kMethods) std::printf("%s\n", m.key.data());
//   gi::method_descriptor(gi::EffectMethod::Prm).name   // "PRM"

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace gi {

/// The five methods of DESIGN.md §1, in that order, then the reflection probes.
enum class EffectMethod : std::uint8_t {
  LightAtlas,
  Prm,
  DirectionalLightMaps,
  Antiradiance,
  BasisRadianceFields,
  ReflectionProbes
};
inline constexpr int kEffectMethodCount = 6;

struct MethodDescriptor {
  EffectMethod method;
  std::string_view key;   ///< "light_atlas": command lines, the manifest, plans, sweeps, docs.
  std::string_view name;  ///< "light atlas": labels, logs, Stats::disabled.
  std::string_view doc;   ///< The method's page in docs/.
};

/// Indexed by EffectMethod.
inline constexpr std::array<MethodDescriptor, kEffectMethodCount> kMethods{{
    {EffectMethod::LightAtlas, "light_atlas", "light atlas", "docs/light_atlas.md"},
    {EffectMethod::Prm, "prm", "PRM", "docs/prm.md"},
    {EffectMethod::DirectionalLightMaps, "dlm", "DLM", "docs/dlm.md"},
    {EffectMethod::Antiradiance, "antiradiance", "antiradiance", "docs/antiradiance.md"},
    {EffectMethod::BasisRadianceFields, "brf", "BRF", "docs/brf.md"},
    {EffectMethod::ReflectionProbes, "reflection_probes", "reflection probes", "docs/reflection_probes.md"},
}};

constexpr const MethodDescriptor& method_descriptor(EffectMethod m) { return kMethods[static_cast<std::size_t>(m)]; }
constexpr std::string_view effect_name(EffectMethod m) { return method_descriptor(m).name; }
/// The method whose key is `key`, or nullopt.
constexpr std::optional<EffectMethod> method_from_key(std::string_view key) {
  for (const MethodDescriptor& d : kMethods)
    if (d.key == key) return d.method;
  return std::nullopt;
}

}  // namespace gi
