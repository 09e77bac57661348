#pragma once
// Plotting a sweep CSV with tools/plot-sweep.py when python3 and matplotlib are present;
// otherwise the exact command to run later.
//   std::string note = gi_sweep::plot_sweep_csv("out/pathtracer_cornell_box.csv");

#include <filesystem>
#include <string>

namespace gi_sweep {

/// The shell command that plots `csv` (the PNG goes next to it, same stem); `frame_cost`:
/// against per-frame milliseconds (`--cost frame`, as the sweep's front) instead of bake time.
std::string plot_command(const std::filesystem::path& csv, bool frame_cost = false);

/// Runs plot_command(csv) when `python3 -c "import matplotlib"` succeeds. Returns a line for
/// the user: where the plot went, or why there is none and the command to run. Never fails.
std::string plot_sweep_csv(const std::filesystem::path& csv, bool frame_cost = false);

}  // namespace gi_sweep
