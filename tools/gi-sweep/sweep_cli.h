#pragma once
// The gi-sweep command line over a given registry (main() passes the shipped methods).
//   gi::SweepRegistry registry; gi::register_builtin_sweep_methods(registry);
//   return gi_sweep::run_cli(argc, argv, registry);

#include "sweep/sweep_registry.h"

namespace gi_sweep {

/// Parses the arguments, runs the sweep, writes the outputs; returns the process exit code:
/// 0 done, 1 an error (named on stderr), 2 bad usage, 130 interrupted (partial results written).
int run_cli(int argc, char** argv, const gi::SweepRegistry& registry);

}  // namespace gi_sweep
