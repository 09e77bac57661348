// gi-sweep: measures a GI method's error against the reference over a grid of its quality
// knobs and writes CSV, a Markdown summary with the Pareto front and presets, and plots.
//   gi-sweep --list
//   gi-sweep --method pathtracer --scene assets/cornell_box.gltf --knob spp=1,4,16 --out out/sweeps
#include "sweep/builtin_methods.h"
#include "sweep_cli.h"

int main(int argc, char** argv) {
  gi::SweepRegistry registry;
  gi::register_builtin_sweep_methods(registry);
  return gi_sweep::run_cli(argc, argv, registry);
}
