// Windowed front end: GLFW window, live input (or a replayed session), the fixed-step
// accumulator, and the Dear ImGui overlay.
#include <algorithm>
#include <cstdio>
#include <iostream>

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>
#include <GLFW/glfw3.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#pragma GCC diagnostic pop

#include <engine/components.h>
#include <engine/gpu/context.h>

#include "demo_run.h"
#include "tool_main.h"

namespace game_demo {

namespace {

constexpr int kMaxStepsPerFrame = 8;  // beyond this the simulation slows down instead of spiralling

constexpr std::pair<int, Key> kKeyMap[] = {{GLFW_KEY_W, Key::W},   {GLFW_KEY_A, Key::A}, {GLFW_KEY_S, Key::S},
                                           {GLFW_KEY_D, Key::D},   {GLFW_KEY_F, Key::F}, {GLFW_KEY_E, Key::E},
                                           {GLFW_KEY_G, Key::G},   {GLFW_KEY_O, Key::O}, {GLFW_KEY_SPACE, Key::Up},
                                           {GLFW_KEY_C, Key::Down}};

// Presses between two polls (GLFW queues key events; a tap is over before the next frame at
// 2-3 frames/s). One window, so one latch.
KeyLatch g_latch;

void on_key(GLFWwindow*, int key, int, int action, int) {
  if (action != GLFW_PRESS || ImGui::GetCurrentContext() == nullptr || ImGui::GetIO().WantCaptureKeyboard) return;
  for (const auto& [glfw_key, k] : kKeyMap)
    if (glfw_key == key) g_latch.press(k);
}

InputFrame live_keys(GLFWwindow* window) {
  InputFrame in;
  if (ImGui::GetIO().WantCaptureKeyboard) return in;
  std::uint32_t held = 0;
  for (const auto& [glfw_key, key] : kKeyMap)
    if (glfwGetKey(window, glfw_key) == GLFW_PRESS) held |= key_bit(key);
  in.keys = g_latch.keys(held);
  return in;
}

void draw_overlay(const RunOptions& o, const RunState& state, const engine::Renderer& renderer,
                  const std::string& indirect, const gi::GISystem* gi, double frame_ms, double fps) {
  const Simulation& sim = *state.sim;
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.6f);
  // At most 45% of the window's width and 40% of its height: long lines wrap, the rest clips.
  const ImVec2 screen = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(0.45f * screen.x, 0.4f * screen.y));
  ImGui::Begin("gi_demo", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoInputs);
  ImGui::PushTextWrapPos(0.45f * screen.x - 20.0f);
  ImGui::Text("%.1f frames/s   last frame %.0f ms   step %llu", fps, frame_ms,
              static_cast<unsigned long long>(sim.frame()));
  ImGui::Separator();
  ImGui::Text("indirect light: %s", indirect.c_str());
  for (const std::string& line : gi_status_lines(gi)) ImGui::TextUnformatted(line.c_str());
  const engine::Light* torch = sim.registry().try_get<engine::Light>(sim.context().flashlight);
  ImGui::Text("flashlight (F): %s   split (G): %s", torch && torch->enabled ? "on" : "off",
              sim.context().split_view ? "direct | full" : "off");
  if (sim.context().tuning.locomotion == Locomotion::Fly)
    ImGui::Text("flying: WASD along the view, mouse look, Space up, C down; %.3g m/s",
                double{sim.registry().get<PlayerController>(sim.context().camera).fly_speed_m_s});
  ImGui::TextUnformatted(describe_exposure(o, renderer).c_str());
  if (state.replay)
    ImGui::Text("replaying %s: %llu / %zu", o.replay_file.c_str(), static_cast<unsigned long long>(sim.frame()),
                state.replay->frames.size());
  if (state.record) ImGui::Text("recording to %s: %zu frames", o.record_file.c_str(), state.record->frames.size());
  ImGui::Separator();
  ImGui::TextUnformatted("render passes (ms, glFinish-timed)");
  for (const auto& p : renderer.last_timings()) ImGui::Text("  %-20s %7.3f", p.name.c_str(), p.ms);
  ImGui::TextUnformatted("systems (CPU ms, last step)");
  for (const auto& t : sim.schedule().last_timings()) ImGui::Text("  %-20s %7.3f", t.name.c_str(), t.cpu_ms);
  ImGui::PopTextWrapPos();
  ImGui::End();
}

void open_imgui(GLFWwindow* window) {
  glfwSetInputMode(window, GLFW_CURSOR, GLFW_CURSOR_DISABLED);
  if (glfwRawMouseMotionSupported()) glfwSetInputMode(window, GLFW_RAW_MOUSE_MOTION, GLFW_TRUE);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  glfwSetKeyCallback(window, on_key);  // before ImGui's backend, which chains to it
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 450");
}

// The wall clock of the window's frames: the last frame's time and the frames per second over
// the last half second or more (frames counted / wall time): an average of per-frame rates
// started from the first, nearly empty frame read 150 at 3.
struct FrameClock {
  double last = 0.0, fps = 0.0, frame_ms = 0.0, window_start = 0.0;
  int window_frames = 0;

  explicit FrameClock(double now) : last(now), window_start(now) {}
  // Advances to `now`; returns the seconds since the last frame.
  double tick(double now) {
    frame_ms = (now - last) * 1000.0;
    ++window_frames;
    if (now - window_start >= 0.5) {
      fps = window_frames / (now - window_start);
      window_start = now;
      window_frames = 0;
    }
    const double elapsed = now - last;
    last = now;
    return elapsed;
  }
};

// The fixed steps the accumulated time holds, from the replay or the live input; true when
// the run is done (the replay or --frames ran out, or a replayed checksum diverged: *status).
bool step_fixed(const RunOptions& o, RunState& state, InputFrame live, double dt, double& accumulator, int& status) {
  Simulation& sim = *state.sim;
  bool done = false;
  while (accumulator >= dt) {
    accumulator -= dt;
    if (state.replay) {
      if (sim.frame() >= state.replay->frames.size()) return true;
      if (!state.step(state.replay->frames[sim.frame()].input)) {
        status = tools::kExitFailure;
        return true;
      }
    } else {
      state.step(live);
      g_latch.stepped();
      live.mouse_dx_px = live.mouse_dy_px = 0.0f;  // the mouse moved once, not once per step
    }
    if (o.frames > 0 && sim.frame() >= o.frames) done = true;
  }
  return done;
}

// Renders the frame to the window's framebuffer with the overlay on top (not yet swapped).
void present_frame(const RunOptions& o, const RunState& state, GLFWwindow* window, engine::Renderer& renderer,
                   RenderClock& render_clock, const std::string& indirect_text, const gi::GISystem* indirect,
                   const FrameClock& clock) {
  const Simulation& sim = *state.sim;
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window, &fb_w, &fb_h);
  renderer.settings().split = split_of(sim);
  renderer.render(sim.registry(), sim.context().camera, render_clock.dt_s(sim));
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, fb_w, fb_h);
  renderer.present(fb_w, fb_h);
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  draw_overlay(o, state, renderer, indirect_text, indirect, clock.frame_ms, clock.fps);
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

}  // namespace

int run_windowed(const RunOptions& o, RunState& state) {
  Simulation& sim = *state.sim;
  auto ctx = engine::GpuContext::create_window("gi_demo", o.width, o.height);
  if (!ctx) {
    std::cerr << "gi_demo: cannot open the window: " << ctx.error().to_string() << '\n';
    return 1;
  }
  GLFWwindow* window = ctx->window();
  std::unique_ptr<gi::GISystem> indirect;                // destroyed before the context
  if (!load_indirect_light(o, sim, indirect)) return 1;  // before the renderer: it adds TEXCOORD_1
  const std::string indirect_text = describe_indirect_light(o, indirect.get());
  auto r = engine::Renderer::create(sim.scene().assets, render_settings(o));
  if (!r) {
    std::cerr << "gi_demo: " << r.error().to_string() << '\n';
    return 1;
  }
  std::unique_ptr<engine::Renderer> renderer = std::move(r).value();
  renderer->set_indirect_light(indirect.get());
  std::cout << "gi_demo: window " << o.width << "x" << o.height << " on " << ctx->description() << '\n';
  std::cout << "gi_demo: indirect light: " << indirect_text << '\n';
  open_imgui(window);

  const double dt = sim.settings().fixed_dt_s;
  double cursor_x = 0, cursor_y = 0;
  glfwGetCursorPos(window, &cursor_x, &cursor_y);
  FrameClock clock(glfwGetTime());
  double accumulator = 0.0;
  int status = 0;
  RenderClock render_clock;
  while (!glfwWindowShouldClose(window)) {
    if (tools::interrupted()) {
      status = tools::kExitCancelled;
      break;
    }
    glfwPollEvents();
    if (glfwGetKey(window, GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
    accumulator = std::min(accumulator + clock.tick(glfwGetTime()), kMaxStepsPerFrame * dt);

    double x = 0, y = 0;
    glfwGetCursorPos(window, &x, &y);
    InputFrame live = live_keys(window);
    live.mouse_dx_px = static_cast<float>(x - cursor_x);
    live.mouse_dy_px = static_cast<float>(y - cursor_y);
    cursor_x = x;
    cursor_y = y;
    const bool done = step_fixed(o, state, live, dt, accumulator, status);

    present_frame(o, state, window, *renderer, render_clock, indirect_text, indirect.get(), clock);
    ctx->swap();
    if (done) break;
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  renderer.reset();
  indirect.reset();
  return status;
}

}  // namespace game_demo
