#include "sweep/sweep_registry.h"

#include <engine/check.h>

#include <algorithm>

namespace gi {
namespace {

bool identifier(std::string_view s, bool allow_dash) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [&](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || (allow_dash && c == '-');
  });
}

}  // namespace

void SweepRegistry::add_method(SweepMethod method) {
  GI_EXPECTS(identifier(method.name, true), "sweep method names are [a-z0-9_-]+");
  GI_EXPECTS(find_method(method.name) == nullptr, "a sweep method with this name is already registered");
  GI_EXPECTS(method.run && method.reference_for, "a sweep method needs run and reference_for functions");
  for (std::size_t i = 0; i < method.knobs.size(); ++i) {
    GI_EXPECTS(identifier(method.knobs[i].name, false), "knob names are [a-z0-9_]+");
    for (std::size_t j = 0; j < i; ++j) {
      GI_EXPECTS(method.knobs[j].name != method.knobs[i].name, "a method declares the same knob twice");
    }
  }
  methods_.push_back(std::move(method));
}

void SweepRegistry::add_reference_provider(ReferenceProvider provider) {
  GI_EXPECTS(identifier(provider.kind, false), "reference kinds are [a-z0-9_]+");
  GI_EXPECTS(find_provider(provider.kind) == nullptr, "a reference provider of this kind is already registered");
  GI_EXPECTS(!provider.version.empty() && provider.compute, "a reference provider needs a version and compute");
  providers_.push_back(std::move(provider));
}

const SweepMethod* SweepRegistry::find_method(std::string_view name) const {
  for (const SweepMethod& m : methods_)
    if (m.name == name) return &m;
  return nullptr;
}

const ReferenceProvider* SweepRegistry::find_provider(std::string_view kind) const {
  for (const ReferenceProvider& p : providers_)
    if (p.kind == kind) return &p;
  return nullptr;
}

}  // namespace gi
