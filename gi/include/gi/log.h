#pragma once
// Messages from the library to its host: what a bake did, why a method was turned off, what
// Embree reported. The library never prints; it calls the host's callback (or drops the
// message when there is none) and keeps what a host must be able to inspect in its stats.
//   gi::LogCallback log = [](gi::LogLevel l, std::string_view m) { std::cerr << m << '\n'; };

#include <cstdint>
#include <functional>
#include <string_view>

namespace gi {

enum class LogLevel : std::uint8_t {
  Info,     ///< Progress worth a line: a stage's summary.
  Warning,  ///< Something the host should know: a method turned off, a fallback taken.
  Error,    ///< A failure also reported through an engine::Error where one is returned.
};

/// Called from the thread that runs the work (never concurrently for one operation).
using LogCallback = std::function<void(LogLevel level, std::string_view message)>;

/// "info", "warning", "error".
std::string_view log_level_name(LogLevel level);

}  // namespace gi
