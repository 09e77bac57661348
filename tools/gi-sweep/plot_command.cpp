#include "plot_command.h"

#include <cstdlib>

namespace gi_sweep {
namespace {

/// A single-quoted shell word.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// The first of `python3` (PATH) and Debian's /usr/bin/python3 that imports matplotlib, or
/// empty. (A PATH python3 from pyenv or a venv does not see Debian's python3-matplotlib.)
std::string python_with_matplotlib() {
  for (const char* python : {"python3", "/usr/bin/python3"}) {
    const std::string probe = std::string(python) + " -c 'import matplotlib' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) return python;
  }
  return {};
}

std::string command_with(const std::string& python, const std::filesystem::path& csv, bool frame_cost) {
  return python + " " + shell_quote(GI_PLOT_SCRIPT) + " " + shell_quote(csv.string()) +
         (frame_cost ? " --cost frame" : "");
}

}  // namespace

std::string plot_command(const std::filesystem::path& csv, bool frame_cost) {
  const std::string python = python_with_matplotlib();
  return command_with(python.empty() ? std::string("python3") : python, csv, frame_cost);
}

std::string plot_sweep_csv(const std::filesystem::path& csv, bool frame_cost) {
  const std::string python = python_with_matplotlib();
  if (python.empty()) {
    return "plots: python3 with matplotlib (Debian: python3-matplotlib) is not available; to plot, run:\n  " +
           command_with("python3", csv, frame_cost);
  }
  const std::string cmd = command_with(python, csv, frame_cost);
  if (std::system((cmd + " >/dev/null").c_str()) != 0) {
    return "plots: the plot script failed; run it to see why:\n  " + cmd;
  }
  std::filesystem::path png = csv;
  png.replace_extension(".png");
  return "plot: " + png.string();
}

}  // namespace gi_sweep
