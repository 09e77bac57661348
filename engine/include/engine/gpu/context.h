#pragma once
// An OpenGL 4.5 core context: headless (EGL surfaceless, Mesa llvmpipe) or in a GLFW window.
//   auto ctx = engine::GpuContext::create_headless();
//   if (!ctx) std::cerr << ctx.error().to_string() << '\n';   // render into FBOs from here on

#include <memory>
#include <string>

#include <engine/result.h>

struct GLFWwindow;

namespace engine {

/// Owns a GL context (and its window, if any); the destructor releases everything. The
/// context is current on the creating thread after create_*(). In debug builds (or with
/// the environment variable GI_GL_DEBUG=1) the context is a debug context and GL debug
/// messages go to the engine log (engine/log.h).
class GpuContext {
 public:
  /// EGL with EGL_PLATFORM_SURFACELESS_MESA: no window system needed. The context has no
  /// default framebuffer; render into framebuffer objects.
  static Result<GpuContext> create_headless();
  /// A GLFW window of `width` x `height` screen coordinates with a 4.5 core context.
  static Result<GpuContext> create_window(const std::string& title, int width, int height);

  GpuContext(GpuContext&&) noexcept;
  GpuContext& operator=(GpuContext&&) noexcept;
  GpuContext(const GpuContext&) = delete;
  GpuContext& operator=(const GpuContext&) = delete;
  ~GpuContext();

  /// Makes this context current on the calling thread.
  void make_current() const;
  /// Presents the back buffer (windowed); no-op when headless.
  void swap() const;
  /// The GLFW window, or nullptr when headless. Owned by the context.
  GLFWwindow* window() const;
  bool headless() const;
  /// GL_VERSION and GL_RENDERER strings, e.g. "4.5 (Core Profile) Mesa 22.3.6 / llvmpipe".
  std::string description() const;

 private:
  struct State;
  explicit GpuContext(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace engine
