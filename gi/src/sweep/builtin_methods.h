#pragma once
// The GI methods and reference providers shipped with the module, registered with the
// sweep harness in one place (gi-sweep calls this at start-up).
//   gi::SweepRegistry registry;
//   gi::register_builtin_sweep_methods(registry);

#include "sweep/sweep_registry.h"

namespace gi {

/// Registers every shipped sweep method and reference provider.
void register_builtin_sweep_methods(SweepRegistry& registry);

}  // namespace gi
