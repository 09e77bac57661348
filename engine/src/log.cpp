#include <engine/log.h>

#include <cstdio>
#include <mutex>
#include <utility>

namespace engine {

namespace {

std::mutex& log_mutex() {
  static std::mutex m;
  return m;
}

LogCallback& current_callback() {
  static LogCallback callback;
  return callback;
}

}  // namespace

LogCallback set_log_callback(LogCallback callback) {
  const std::lock_guard<std::mutex> lock(log_mutex());
  return std::exchange(current_callback(), std::move(callback));
}

void log_message(LogLevel level, std::string_view message) {
  const std::lock_guard<std::mutex> lock(log_mutex());
  if (const LogCallback& callback = current_callback()) {
    callback(level, message);
    return;
  }
  const std::string_view name = log_level_name(level);
  std::fprintf(stderr, "engine %.*s: %.*s\n", static_cast<int>(name.size()), name.data(),
               static_cast<int>(message.size()), message.data());
}

std::string_view log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::Info:
      return "info";
    case LogLevel::Warning:
      return "warning";
    case LogLevel::Error:
      return "error";
  }
  return "info";
}

}  // namespace engine
