#include "bake/bake_stage.h"

#include <cstdarg>
#include <cstdio>
#include <filesystem>

namespace gi {

std::string format_line(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

std::string scene_file_name(const BakeInput& input) {
  return input.name.empty() ? std::string("the scene") : std::filesystem::path(input.name).filename().string();
}

}  // namespace gi
