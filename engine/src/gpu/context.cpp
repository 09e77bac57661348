#include <engine/gpu/context.h>
#include <engine/log.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace engine {

namespace {

bool debug_requested() {
#ifndef NDEBUG
  return true;
#else
  const char* v = std::getenv("GI_GL_DEBUG");
  return v != nullptr && v[0] == '1';
#endif
}

void GLAPIENTRY print_debug_message(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei /*length*/,
                                    const GLchar* message, const void* /*user*/) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
  char head[96];
  std::snprintf(head, sizeof head, "GL debug [source 0x%x type 0x%x id %u severity 0x%x]: ", source, type, id,
                severity);
  log_message(type == GL_DEBUG_TYPE_ERROR ? LogLevel::Error : LogLevel::Warning, std::string(head) + message);
}

void install_debug_output() {
  if (!debug_requested()) return;
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  if ((flags & GL_CONTEXT_FLAG_DEBUG_BIT) == 0) return;
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(print_debug_message, nullptr);
}

// The surfaceless EGL display is process-wide; it is terminated when the last headless
// context goes away.
std::mutex g_egl_mutex;
int g_egl_users = 0;

std::string egl_error_text(const char* what) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%s failed (EGL error 0x%x)", what, static_cast<unsigned>(eglGetError()));
  return buf;
}

int g_glfw_users = 0;

}  // namespace

struct GpuContext::State {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  GLFWwindow* window = nullptr;

  ~State() {
    if (window != nullptr) {
      glfwDestroyWindow(window);
      if (--g_glfw_users == 0) glfwTerminate();
    }
    if (context != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == context) eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
      std::lock_guard lock(g_egl_mutex);
      if (--g_egl_users == 0) eglTerminate(display);
    }
  }
};

GpuContext::GpuContext(std::unique_ptr<State> state) : state_(std::move(state)) {}
GpuContext::GpuContext(GpuContext&&) noexcept = default;
GpuContext& GpuContext::operator=(GpuContext&&) noexcept = default;
GpuContext::~GpuContext() = default;

Result<GpuContext> GpuContext::create_headless() {
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) return Error{"", "EGL", "eglGetPlatformDisplayEXT is not available"};
  EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) return Error{"", "EGL", egl_error_text("eglGetPlatformDisplayEXT(SURFACELESS_MESA)")};
  {
    std::lock_guard lock(g_egl_mutex);
    EGLint major = 0;
    EGLint minor = 0;
    if (eglInitialize(display, &major, &minor) == EGL_FALSE) return Error{"", "EGL", egl_error_text("eglInitialize")};
    ++g_egl_users;
  }
  auto state = std::make_unique<State>();
  state->display = display;
  if (eglBindAPI(EGL_OPENGL_API) == EGL_FALSE) {
    std::lock_guard lock(g_egl_mutex);
    if (--g_egl_users == 0) eglTerminate(display);
    return Error{"", "EGL", egl_error_text("eglBindAPI(EGL_OPENGL_API)")};
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                       4,
                                       EGL_CONTEXT_MINOR_VERSION,
                                       5,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                       EGL_CONTEXT_OPENGL_DEBUG,
                                       debug_requested() ? EGL_TRUE : EGL_FALSE,
                                       EGL_NONE};
  // Surfaceless contexts need no config (EGL_KHR_no_config_context).
  EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT) {
    std::lock_guard lock(g_egl_mutex);
    const std::string msg = egl_error_text("eglCreateContext(OpenGL 4.5 core)");
    if (--g_egl_users == 0) eglTerminate(display);
    state->display = EGL_NO_DISPLAY;
    return Error{"", "EGL", msg};
  }
  state->context = context;
  if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) == EGL_FALSE)
    return Error{"", "EGL", egl_error_text("eglMakeCurrent(EGL_NO_SURFACE)")};
  install_debug_output();
  return GpuContext(std::move(state));
}

Result<GpuContext> GpuContext::create_window(const std::string& title, int width, int height) {
  GI_EXPECTS(width > 0 && height > 0, "window size must be positive");
  if (g_glfw_users == 0 && glfwInit() == GLFW_FALSE) {
    const char* description = nullptr;
    glfwGetError(&description);
    return Error{"", "GLFW", std::string("glfwInit failed: ") + (description ? description : "unknown error")};
  }
  ++g_glfw_users;
  auto state = std::make_unique<State>();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, debug_requested() ? GLFW_TRUE : GLFW_FALSE);
  state->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (state->window == nullptr) {
    const char* description = nullptr;
    glfwGetError(&description);
    if (--g_glfw_users == 0) glfwTerminate();
    return Error{
        "", "GLFW",
        std::string("glfwCreateWindow (OpenGL 4.5 core) failed: ") + (description ? description : "unknown error")};
  }
  glfwMakeContextCurrent(state->window);
  glfwSwapInterval(0);
  install_debug_output();
  return GpuContext(std::move(state));
}

void GpuContext::make_current() const {
  GI_EXPECTS(state_ != nullptr, "make_current() on a moved-from GpuContext");
  if (state_->window != nullptr)
    glfwMakeContextCurrent(state_->window);
  else
    eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, state_->context);
}

void GpuContext::swap() const {
  GI_EXPECTS(state_ != nullptr, "swap() on a moved-from GpuContext");
  if (state_->window != nullptr) glfwSwapBuffers(state_->window);
}

GLFWwindow* GpuContext::window() const { return state_ ? state_->window : nullptr; }
bool GpuContext::headless() const { return state_ && state_->window == nullptr; }

std::string GpuContext::description() const {
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return std::string(version ? version : "?") + " / " + (renderer ? renderer : "?");
}

}  // namespace engine
