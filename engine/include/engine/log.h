#pragma once
// The engine's messages to its host (a glTF file's skipped parts, a shader variant that failed
// to build, the GL driver's debug output) go through one callback, as gi's do (gi/log.h). By
// default they are printed on stderr as "engine <level>: <message>"; a host routes them to its
// own log, or silences them, with set_log_callback.
//   engine::set_log_callback([](engine::LogLevel l, std::string_view m) { my_log(l, m); });
//   engine::set_log_callback(nullptr);  // back to stderr

#include <cstdint>
#include <functional>
#include <string_view>

namespace engine {

enum class LogLevel : std::uint8_t {
  Info,     ///< Worth a line, nothing wrong: e.g. the GL driver's notifications.
  Warning,  ///< Something the host should know: part of a file skipped, a fallback taken.
  Error,    ///< A failure; where a call fails because of it, it also returns an engine::Error.
};

/// Receives every engine message. May be called from any thread that runs engine code (the
/// glTF loader's, the GL context's); calls are serialised, never concurrent.
using LogCallback = std::function<void(LogLevel level, std::string_view message)>;

/// Replaces the callback for the whole process; an empty callback restores the default
/// (stderr). Returns the previous one (empty when it was the default), for tests to restore.
LogCallback set_log_callback(LogCallback callback);

/// Sends `message` to the callback (or stderr). For engine code; hosts may use it too.
void log_message(LogLevel level, std::string_view message);

/// "info", "warning", "error".
std::string_view log_level_name(LogLevel level);

}  // namespace engine
