#include "sweep/sweep_progress_bar.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gi {

std::string format_duration(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "--:--";
  const long long s = static_cast<long long>(std::llround(seconds));
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof(buf), "%lld:%02lld:%02lld", s / 3600, (s / 60) % 60, s % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%lld:%02lld", s / 60, s % 60);
  }
  return buf;
}

std::string format_sweep_progress(const SweepProgress& p, double elapsed_s, int bar_width) {
  const double total = static_cast<double>(std::max<std::size_t>(p.units_total, 1));
  const double f =
      std::clamp((static_cast<double>(p.units_done) + std::clamp(p.current_fraction, 0.0, 1.0)) / total, 0.0, 1.0);
  const int filled = static_cast<int>(f * bar_width);
  std::string s = "[" + std::string(static_cast<std::size_t>(filled), '#') +
                  std::string(static_cast<std::size_t>(bar_width - filled), '.') + "] ";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%zu/%zu %3d%%", p.units_done, p.units_total, static_cast<int>(f * 100.0));
  s += buf;
  if (!p.current.empty()) {
    std::snprintf(buf, sizeof(buf), " (%d%%)", static_cast<int>(std::clamp(p.current_fraction, 0.0, 1.0) * 100.0));
    s += "  " + p.current + buf;
  }
  s += "  elapsed " + format_duration(elapsed_s) + "  ETA " +
       format_duration(f > 0.0 ? elapsed_s * (1.0 - f) / f : -1.0);
  return s;
}

SweepProgressBar::SweepProgressBar(std::ostream& out, bool terminal, double min_interval_s)
    : out_(out), terminal_(terminal), min_interval_s_(min_interval_s) {}

bool SweepProgressBar::update(const SweepProgress& p) {
  const auto now = std::chrono::steady_clock::now();
  const bool unit_changed = p.units_done != last_units_done_;
  const double since = std::chrono::duration<double>(now - last_draw_).count();
  // Not a terminal: one line per unit, no redraws (logs stay readable).
  if (unit_changed || (terminal_ && since >= min_interval_s_)) {
    std::string line = format_sweep_progress(p, std::chrono::duration<double>(now - start_).count());
    if (terminal_) {
      const std::size_t width = line.size();
      if (width < last_width_) line += std::string(last_width_ - width, ' ');
      out_ << '\r' << line << std::flush;
      last_width_ = width;
    } else {
      out_ << line << '\n' << std::flush;
    }
    last_draw_ = now;
    last_units_done_ = p.units_done;
  }
  return !cancel_;
}

void SweepProgressBar::finish() {
  if (terminal_ && last_width_ > 0) out_ << '\n' << std::flush;
  last_width_ = 0;
}

}  // namespace gi
