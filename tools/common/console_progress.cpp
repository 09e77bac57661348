#include "console_progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "tool_main.h"

namespace tools {

std::string format_duration(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) return "--:--";
  const long long s = std::llround(seconds);
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", s / 3600, (s / 60) % 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lld:%02lld", s / 60, s % 60);
  }
  return buf;
}

std::string format_progress(std::string_view label, double fraction, double elapsed_s, std::string_view detail,
                            int bar_width) {
  const double f = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(f * bar_width);
  std::string s(label);
  s += " [" + std::string(static_cast<std::size_t>(filled), '#') +
       std::string(static_cast<std::size_t>(bar_width - filled), '.') + "] ";
  char pct[16];
  std::snprintf(pct, sizeof pct, "%3d%%", static_cast<int>(f * 100.0));
  s += pct;
  if (!detail.empty()) s += "  " + std::string(detail);
  s += "  elapsed " + format_duration(elapsed_s) + "  ETA " +
       format_duration(f > 0.0 ? elapsed_s * (1.0 - f) / f : -1.0);
  return s;
}

ConsoleProgress::ConsoleProgress(std::FILE* out) : ConsoleProgress(out, isatty(fileno(out)) != 0) {}

ConsoleProgress::ConsoleProgress(std::FILE* out, bool terminal) : out_(out), terminal_(terminal) {}

ConsoleProgress::~ConsoleProgress() { finish(); }

bool ConsoleProgress::update(std::string_view label, double fraction, std::string_view detail) {
  const auto now = Clock::now();
  const bool new_label = label != label_;
  if (new_label) {
    finish();
    label_ = std::string(label);
    start_ = now;
  }
  const bool done = fraction >= 1.0;
  const auto interval = std::chrono::milliseconds(terminal_ ? 100 : 2000);
  if (new_label || done || now - last_draw_ >= interval) {
    last_draw_ = now;
    const std::string line =
        format_progress(label_, fraction, std::chrono::duration<double>(now - start_).count(), detail);
    if (terminal_) {
      std::fprintf(out_, "\r%s\033[K", line.c_str());
      line_open_ = true;
      if (done) finish();
    } else {
      std::fprintf(out_, "%s\n", line.c_str());
    }
    std::fflush(out_);
  }
  return !interrupted();
}

void ConsoleProgress::finish() {
  if (line_open_) std::fputc('\n', out_);
  line_open_ = false;
}

gi::ProgressCallback ConsoleProgress::stage(std::string label) {
  return [this, label = std::move(label)](double f) { return update(label, f); };
}

gi::StageProgressCallback ConsoleProgress::stages() {
  return [this](std::string_view stage, double f) { return update(stage, f); };
}

}  // namespace tools
