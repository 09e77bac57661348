#pragma once
// The GL context of gi's GPU tests: a headless one (EGL surfaceless on Mesa llvmpipe here), or
// the test fails and the program stops. A GPU test never skips, so a machine without the
// context is a failure that names why.
//   TEST(X, Y) { auto ctx = gltest::headless_or_fail(); ... }

#include <gtest/gtest.h>
#include <engine/gpu/context.h>

#include <cstdlib>
#include <utility>

namespace gltest {

inline engine::GpuContext headless_or_fail() {
  auto ctx = engine::GpuContext::create_headless();
  if (!ctx) {
    ADD_FAILURE() << "headless GL context creation failed: " << ctx.error().to_string();
    std::abort();
  }
  return std::move(ctx).value();
}

}  // namespace gltest
