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

}  // namespace

std::string plot_command(const std::filesystem::path& csv) {
  return "python3 " + shell_quote(GI_PLOT_SCRIPT) + " " + shell_quote(csv.string());
}

std::string plot_sweep_csv(const std::filesystem::path& csv) {
  const std::string cmd = plot_command(csv);
  if (std::system("python3 -c 'import matplotlib' >/dev/null 2>&1") != 0) {
    return "plots: python3 with matplotlib (Debian: python3-matplotlib) is not available; to plot, run:\n  " + cmd;
  }
  if (std::system((cmd + " >/dev/null").c_str()) != 0) {
    return "plots: the plot script failed; run it to see why:\n  " + cmd;
  }
  std::filesystem::path png = csv;
  png.replace_extension(".png");
  return "plot: " + png.string();
}

}  // namespace gi_sweep
