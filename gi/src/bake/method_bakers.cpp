#include "bake/method_bakers.h"

#include <array>
#include <cstdlib>

namespace gi {

namespace {

// The order bakes ran in before the table: each method's files do not depend on it, but
// antiradiance stores its texel blends for the atlas a method before it wrote.
constexpr std::array kBakers = {
    MethodBakerEntry{EffectMethod::LightAtlas, &bake_light_atlas_method},
    MethodBakerEntry{EffectMethod::Prm, &bake_prm_method},
    MethodBakerEntry{EffectMethod::DirectionalLightMaps, &bake_dlm_method},
    MethodBakerEntry{EffectMethod::BasisRadianceFields, &bake_brf_method},
    MethodBakerEntry{EffectMethod::Antiradiance, &bake_antiradiance_method},
    MethodBakerEntry{EffectMethod::ReflectionProbes, &bake_reflection_probes_method},
};

}  // namespace

std::span<const MethodBakerEntry> method_bakers() { return kBakers; }

const MethodBakerEntry& method_baker(EffectMethod m) {
  for (const MethodBakerEntry& e : kBakers)
    if (e.method == m) return e;
  std::abort();  // every EffectMethod has a row (MethodBakers.EveryMethodHasABaker)
}

}  // namespace gi
