#pragma once
// The list of GI methods and reference providers the sweep harness knows. Each method
// registers itself at start-up (see builtin_methods.h); the harness never names them.
//   gi::SweepRegistry registry;
//   gi::register_builtin_sweep_methods(registry);  const gi::SweepMethod* m = registry.find_method("light_atlas");

#include <memory>
#include <string_view>
#include <vector>

#include "sweep/sweep_method.h"

namespace gi {

class SweepRegistry {
 public:
  /// Adds a method. Preconditions: a valid, unused name, a run and a reference_for function,
  /// unique knob names with valid names.
  void add_method(SweepMethod method);
  /// Adds a reference provider. Preconditions: a valid, unused kind, a version and compute.
  void add_reference_provider(ReferenceProvider provider);

  /// The method called `name`, or nullptr.
  const SweepMethod* find_method(std::string_view name) const;
  /// The provider of `kind`, or nullptr.
  const ReferenceProvider* find_provider(std::string_view kind) const;

  /// In registration order.
  const std::vector<SweepMethod>& methods() const { return methods_; }
  const std::vector<ReferenceProvider>& providers() const { return providers_; }

 private:
  std::vector<SweepMethod> methods_;
  std::vector<ReferenceProvider> providers_;
};

}  // namespace gi
