#pragma once
// Precondition checks for programmer errors (not for bad input files: those return an
// engine::Error). A failed check prints the broken contract with its location and aborts,
// in every build type; death tests cover them.

#include <cstdio>
#include <cstdlib>

namespace engine::detail {
[[noreturn]] inline void check_failed(const char* expr, const char* message, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: precondition failed: %s (%s)\n", file, line, message, expr);
  std::fflush(stderr);
  std::abort();
}
}  // namespace engine::detail

/// GI_EXPECTS(cond, "what the caller must guarantee"): aborts with the message when cond is false.
#define GI_EXPECTS(cond, message)                                                    \
  do {                                                                               \
    if (!(cond)) ::engine::detail::check_failed(#cond, message, __FILE__, __LINE__); \
  } while (false)
