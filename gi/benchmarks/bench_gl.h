#pragma once
// The headless GL context the GPU benchmarks share: created on first use, the process ends
// with a message when there is none (a GPU benchmark never runs without GL).
//   (void)bench::gl_context();   // before any GL call

#include <cstdio>
#include <cstdlib>

#include <engine/gpu/context.h>

namespace bench {

inline engine::GpuContext& gl_context() {
  static engine::GpuContext ctx = [] {
    auto c = engine::GpuContext::create_headless();
    if (!c) {
      std::fprintf(stderr, "headless GL context creation failed: %s\n", c.error().to_string().c_str());
      std::exit(1);
    }
    return std::move(c).value();
  }();
  return ctx;
}

}  // namespace bench
