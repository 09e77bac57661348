#pragma once
// The command-line tools' one progress bar, on stderr:
//   "light atlas [##########..........]  42%  elapsed 0:12  ETA 0:16"
// redrawn in place on a terminal (at most every 0.1 s), one line every 2 s otherwise (CI
// logs); a new label ends the previous line. Every callback it hands out returns false once
// the user pressed Ctrl-C (tools::interrupted()), which cancels the work.
//   tools::ConsoleProgress bar;
//   settings.progress = bar.stage("render");                  // gi::ProgressCallback
//   host.progress = bar.stages();                             // gi::StageProgressCallback

#include <gi/progress.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace tools {

/// "1:05", "1:02:03", or "--:--" for a negative or unknown time.
std::string format_duration(double seconds);

/// "<label> [####......] 42%  <detail>  elapsed 0:12  ETA 0:16" for a fraction in [0, 1];
/// ETA = elapsed x (1 - f) / f.
std::string format_progress(std::string_view label, double fraction, double elapsed_s, std::string_view detail = {},
                            int bar_width = 20);

class ConsoleProgress {
 public:
  /// Draws on `out` (stderr by default); `terminal` chooses in-place redraws.
  explicit ConsoleProgress(std::FILE* out = stderr);
  ConsoleProgress(std::FILE* out, bool terminal);
  ~ConsoleProgress();
  ConsoleProgress(const ConsoleProgress&) = delete;
  ConsoleProgress& operator=(const ConsoleProgress&) = delete;

  /// Draws (throttled; always at 100% and on a new label). Returns !tools::interrupted().
  bool update(std::string_view label, double fraction, std::string_view detail = {});
  /// Ends the current line, if any.
  void finish();

  /// A callback drawing under `label`; the clock restarts for it.
  gi::ProgressCallback stage(std::string label);
  /// A callback for staged work (the label is the stage's name).
  gi::StageProgressCallback stages();

 private:
  using Clock = std::chrono::steady_clock;
  std::FILE* out_;
  bool terminal_;
  std::string label_;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_draw_{};
  bool line_open_ = false;
};

}  // namespace tools
