// Headless front end: EGL surfaceless rendering, inputs from a ScriptedPilot or a replayed
// session, frames written as PNG/EXR, a timing summary at the end.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <numeric>
#include <vector>

#include <engine/components.h>
#include <engine/gpu/context.h>
#include <engine/image.h>

#include "demo_run.h"
#include "tool_main.h"

namespace game_demo {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct Summary {
  std::vector<double> values;
  void add(double v) { values.push_back(v); }
  void print(const char* label) const {
    if (values.empty()) return;
    std::vector<double> v = values;
    std::sort(v.begin(), v.end());
    const double mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
    const auto pct = [&](double p) {
      return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
    };
    std::printf("  %-22s mean %8.3f  median %8.3f  p95 %8.3f  max %8.3f ms\n", label, mean, pct(0.5), pct(0.95),
                v.back());
  }
};

// The GL context, GI system and renderer of a rendering run, destroyed in that order's reverse.
struct HeadlessGpu {
  std::optional<engine::GpuContext> gpu;
  std::unique_ptr<gi::GISystem> indirect;  // destroyed before gpu
  std::unique_ptr<engine::Renderer> renderer;
};

// Creates the headless context, the GI system and the renderer; false after saying why not.
bool open_gpu(const RunOptions& o, Simulation& sim, HeadlessGpu& g) {
  auto ctx = engine::GpuContext::create_headless();
  if (!ctx) {
    std::cerr << "gi_demo: cannot create the headless GL context: " << ctx.error().to_string() << '\n';
    return false;
  }
  g.gpu.emplace(std::move(ctx).value());
  if (!load_indirect_light(o, sim, g.indirect)) return false;  // before the renderer: it adds TEXCOORD_1
  auto r = engine::Renderer::create(sim.scene().assets, render_settings(o));
  if (!r) {
    std::cerr << "gi_demo: " << r.error().to_string() << '\n';
    return false;
  }
  g.renderer = std::move(r).value();
  g.renderer->set_indirect_light(g.indirect.get());
  std::cout << "gi_demo: headless " << o.width << "x" << o.height << " on " << g.gpu->description() << '\n';
  std::cout << "gi_demo: indirect light: " << describe_indirect_light(o, g.indirect.get()) << '\n';
  return true;
}

// What the run measured, per frame.
struct RunTimings {
  Summary step_ms, render_ms, write_ms, total_ms;
  std::map<std::string, Summary> systems, passes;
  std::vector<std::string> system_order, pass_order;
  std::uint64_t shadow_views_drawn = 0, shadow_views_cached = 0, shadow_views_unseen = 0, rendered_frames = 0,
                light_groups = 0;

  void add_systems(const Simulation& sim) {
    for (const auto& t : sim.schedule().last_timings()) {
      if (!systems.contains(t.name)) system_order.push_back(t.name);
      systems[t.name].add(t.cpu_ms);
    }
  }
  void add_render(const engine::Renderer& renderer) {
    for (const auto& p : renderer.last_timings()) {
      if (!passes.contains(p.name)) pass_order.push_back(p.name);
      passes[p.name].add(p.ms);
    }
    shadow_views_drawn += static_cast<std::uint64_t>(renderer.last_shadow_maps_rendered());
    shadow_views_cached += static_cast<std::uint64_t>(renderer.last_shadow_maps_over_static_depth());
    shadow_views_unseen += static_cast<std::uint64_t>(renderer.last_shadow_maps_unseen());
    light_groups += static_cast<std::uint64_t>(renderer.last_light_groups());
    ++rendered_frames;
  }
  void print() const {
    std::printf("per frame:\n");
    total_ms.print("total");
    step_ms.print("simulation step");
    render_ms.print("render");
    write_ms.print("image write");
    std::printf("systems (CPU):\n");
    for (const auto& n : system_order) systems.at(n).print(n.c_str());
    if (!pass_order.empty()) std::printf("render passes:\n");
    for (const auto& n : pass_order) passes.at(n).print(n.c_str());
    if (rendered_frames > 0)
      std::printf(
          "  shadow-map views drawn per frame: %.2f (the others kept: their light and casters did not move), "
          "%.2f of them over their static casters' cached depth (only dynamic casters moved); %.2f changed "
          "but left undrawn (the camera cannot see into them)\n",
          static_cast<double>(shadow_views_drawn) / static_cast<double>(rendered_frames),
          static_cast<double>(shadow_views_cached) / static_cast<double>(rendered_frames),
          static_cast<double>(shadow_views_unseen) / static_cast<double>(rendered_frames));
    if (rendered_frames > 0)
      std::printf(
          "  light sets per frame: %.2f (pixels shaded with only the lights that can reach them; 1: every light "
          "everywhere)\n",
          static_cast<double>(light_groups) / static_cast<double>(rendered_frames));
  }
};

// Writes DIR/frame_NNNN.png (and .exr with --exr); false after saying why not.
bool write_frame(const RunOptions& o, const engine::Renderer& renderer, std::uint64_t i) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04llu", static_cast<unsigned long long>(i));
  const std::filesystem::path base = std::filesystem::path(o.out_dir) / name;
  engine::Status s = engine::save_png(base.string() + ".png", renderer.read_ldr());
  if (s && o.exr) s = engine::save_exr(base.string() + ".exr", renderer.read_hdr());
  if (!s) {
    std::cerr << "gi_demo: " << s.error().to_string() << '\n';
    return false;
  }
  return true;
}

void print_position(const Simulation& sim, std::uint64_t i, const InputFrame& input) {
  const glm::vec3 eye = sim.registry().get<engine::Transform>(sim.context().camera).position;
  std::printf("frame %4llu eye (%.2f, %.2f, %.2f) yaw %.2f keys 0x%x\n", static_cast<unsigned long long>(i),
              double{eye.x}, double{eye.y}, double{eye.z},
              double{sim.registry().get<PlayerController>(sim.context().camera).yaw_rad}, input.keys);
}

// --frames, else the replay's length (never past it), else 120.
std::uint64_t frames_to_run(const RunOptions& o, const RunState& state) {
  std::uint64_t frames = o.frames;
  if (state.replay)
    frames = frames == 0 ? state.replay->frames.size() : std::min<std::uint64_t>(frames, state.replay->frames.size());
  else if (frames == 0)
    frames = 120;
  return frames;
}

}  // namespace

int run_headless(const RunOptions& o, RunState& state) {
  Simulation& sim = *state.sim;
  const std::uint64_t frames = frames_to_run(o, state);
  std::optional<ScriptedPilot> pilot;
  if (!state.replay) pilot.emplace(sim, *script_from_name(o.script), frames);
  if (pilot && o.verbose)
    for (const glm::vec3& p : pilot->waypoints())
      std::printf("waypoint (%.2f, %.2f, %.2f)\n", double{p.x}, double{p.y}, double{p.z});

  HeadlessGpu g;
  if (!o.no_render && !open_gpu(o, sim, g)) return 1;
  engine::Renderer* renderer = g.renderer.get();
  if (!o.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec) {
      std::cerr << "gi_demo: cannot create " << o.out_dir << ": " << ec.message() << '\n';
      return 1;
    }
  }

  RunTimings timings;
  RenderClock render_clock;
  const auto run_t0 = Clock::now();
  for (std::uint64_t i = 0; i < frames; ++i) {
    if (tools::interrupted()) return tools::kExitCancelled;  // Ctrl-C: the frames written so far stay whole
    const auto t0 = Clock::now();
    const InputFrame input = state.replay ? state.replay->frames[i].input : pilot->next(sim);
    if (!state.step(input)) return tools::kExitFailure;
    timings.step_ms.add(ms_since(t0));
    if (o.verbose && i % 60 == 0) print_position(sim, i, input);
    timings.add_systems(sim);
    const bool written = !o.out_dir.empty() && i % o.every == 0;
    if (renderer && (written || !o.only_written)) {
      const auto t1 = Clock::now();
      renderer->settings().split = split_of(sim);
      renderer->render(sim.registry(), sim.context().camera, render_clock.dt_s(sim));
      timings.render_ms.add(ms_since(t1));
      timings.add_render(*renderer);
      if (written) {
        const auto t2 = Clock::now();
        if (!write_frame(o, *renderer, i)) return 1;
        timings.write_ms.add(ms_since(t2));
      }
    }
    timings.total_ms.add(ms_since(t0));
  }
  const double wall_s = ms_since(run_t0) / 1000.0;
  std::printf("gi_demo: %llu frames in %.2f s (%.1f frames/s)%s\n", static_cast<unsigned long long>(frames), wall_s,
              static_cast<double>(frames) / wall_s, renderer ? "" : ", simulation only");
  timings.print();
  if (timings.rendered_frames > 0) std::printf("  %s at the last frame\n", describe_exposure(o, *renderer).c_str());
  for (const std::string& line : gi_status_lines(g.indirect.get())) std::printf("%s\n", line.c_str());
  std::printf("final state checksum 0x%016llx after frame %llu\n", static_cast<unsigned long long>(sim.checksum()),
              static_cast<unsigned long long>(sim.frame()));
  return 0;
}

}  // namespace game_demo
