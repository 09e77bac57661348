// gi_demo: the playable demo level. See `gi_demo --help`.
//   gi_demo                                   window: WASD + mouse, F flashlight, E push, G split, Esc quits
//   gi_demo --scene any.gltf                  its first camera or a framing view; flies: WASD, mouse, Space/C
//   gi_demo --headless --frames 120 --out /tmp/frames
//   gi_demo --headless --script push_crates --frames 600 --record s.girec --no-render
//   gi_demo --headless --replay tests/sessions/push_crates.girec
//   gi_demo --gi-bundle out/demo_level.gibake        light the static world with its bake (light atlas, PRM)
//   gi_demo --exposure 0.3 | --ev100 15             fixed exposure instead of automatic (docs/exposure.md)
#include <engine/sky.h>
#include <gi/gi_system.h>

#include <cstdio>
#include <iostream>
#include <CLI/CLI.hpp>

#include "demo_run.h"
#include "tool_main.h"

namespace game_demo {

bool RunState::step(const InputFrame& input) {
  const std::uint64_t index = sim->frame();
  const std::uint64_t sum = sim->step(input);
  if (record) record->frames.push_back(SessionFrame{input, sum});
  if (replay && index < replay->frames.size() && replay->frames[index].checksum != sum) {
    ++mismatches;
    std::cerr << "gi_demo: replay diverged at " << describe(ReplayMismatch{index, replay->frames[index].checksum, sum})
              << '\n';
    return false;
  }
  return true;
}

bool RunState::finish_recording(const std::string& path) const {
  if (!record) return true;
  const engine::Status saved = save_session(path, *record);
  if (!saved) {
    std::cerr << "gi_demo: cannot write the recording: " << saved.error().to_string() << '\n';
    return false;
  }
  std::cout << "recorded " << record->frames.size() << " frames to " << path << '\n';
  return true;
}

bool load_indirect_light(const RunOptions& o, Simulation& sim, std::unique_ptr<gi::GISystem>& system) {
  system.reset();
  if (o.gi_bundle.empty()) return true;
  gi::GISystemSettings settings;
  settings.log = [](gi::LogLevel level, std::string_view message) {
    std::cerr << "gi_demo: gi " << gi::log_level_name(level) << ": " << message << '\n';
  };
  auto loaded = gi::GISystem::load(o.gi_bundle, sim.scene(), settings);
  if (!loaded) {
    std::cerr << "gi_demo: cannot use --gi-bundle " << o.gi_bundle << ": " << loaded.error().to_string() << '\n';
    return false;
  }
  system = std::move(loaded).value();
  return true;
}

engine::RenderSettings render_settings(const RunOptions& o) {
  engine::RenderSettings s{.width = o.width,
                           .height = o.height,
                           .exposure = o.exposure,
                           .exposure_mode = o.exposure_mode,
                           .ev100 = o.ev100,
                           .area_soft_shadows = o.area_soft_shadows,
                           .area_shadow_res = o.area_shadow_res,
                           .light_reach_culling = o.light_reach_culling,
                           .flat_shading = o.flat_shading,
                           .warn = [](const std::string& line) { std::cerr << "gi_demo: " << line << '\n'; }};
  s.auto_exposure.compensation_ev = o.exposure_compensation_ev;
  return s;
}

std::string describe_exposure(const RunOptions& o, const engine::Renderer& renderer) {
  const engine::ExposureReading e = renderer.read_exposure();
  char line[160];
  if (e.metered)
    std::snprintf(line, sizeof line, "exposure: automatic, EV100 %.2f (target %.2f, compensation %+.1f EV), x%.4g",
                  double{e.ev100}, double{e.target_ev100}, double{o.exposure_compensation_ev}, double{e.exposure});
  else if (o.exposure_mode == engine::ExposureMode::FixedEv100)
    std::snprintf(line, sizeof line, "exposure: fixed EV100 %.2f (--ev100), x%.4g", double{e.ev100},
                  double{e.exposure});
  else
    std::snprintf(line, sizeof line, "exposure: fixed x%.4g (--exposure; EV100 %.2f)", double{e.exposure},
                  double{e.ev100});
  return line;
}

std::string describe_indirect_light(const RunOptions& o, const gi::GISystem* system) {
  if (system == nullptr) return "constant ambient (stand-in), no GI bundle";
  return std::string(system->label()) + " from " + o.gi_bundle;
}

std::vector<std::string> gi_status_lines(const gi::GISystem* system) {
  std::vector<std::string> lines;
  if (system == nullptr) return lines;
  std::string text = system->describe();
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = text.find('\n', at);
    lines.push_back(text.substr(at, end == std::string::npos ? std::string::npos : end - at));
    if (end == std::string::npos) break;
    at = end + 1;
  }
  const gi::GISystem::Stats& st = system->stats();
  char line[256];
  std::snprintf(line, sizeof line,
                "GI frames %llu: %llu idle, PRM re-lit %llu (%.2f ms), BRF updated %llu (%llu with motion)",
                static_cast<unsigned long long>(st.frames), static_cast<unsigned long long>(st.idle_frames),
                static_cast<unsigned long long>(st.prm_updates), st.last_prm_ms,
                static_cast<unsigned long long>(st.brf_updates), static_cast<unsigned long long>(st.brf_moves));
  lines.emplace_back(line);
  if (st.dynamic_objects > 0) {
    std::snprintf(line, sizeof line,
                  "BRF last update: %.2f ms CPU (direct, probes) + %.2f ms GPU; pairs %zu live, %zu reused, %zu culled",
                  st.last_brf_cpu_ms, st.last_brf_gpu_ms, st.brf_pairs_evaluated, st.brf_pairs_reused,
                  st.brf_pairs_culled);
    lines.emplace_back(line);
  }
  if (st.antiradiance_updates > 0) {
    std::snprintf(
        line, sizeof line,
        "antiradiance: %llu door moves solved, last %.0f ms (%zu elements relinked; near-door visibility %.0f "
        "ms of it)",
        static_cast<unsigned long long>(st.antiradiance_updates), st.last_antiradiance_ms,
        st.antiradiance_relinked_elements, st.antiradiance_near_ms);
    lines.emplace_back(line);
  }
  for (const std::string& off : st.disabled) lines.push_back("off: " + off);
  return lines;
}

}  // namespace game_demo

namespace {

using namespace game_demo;

// The renderer's choices as the command line spells them, and the options whose presence counts.
struct RenderChoices {
  std::string area_shadows = "soft";
  std::string light_reach = "on";
  std::string area_shadow_res = "half";
  std::string shading = "full";
  CLI::Option* width = nullptr;
  CLI::Option* height = nullptr;
  CLI::Option* exposure = nullptr;
  CLI::Option* ev100 = nullptr;
};

void add_render_options(CLI::App& app, RunOptions& o, RenderChoices& c) {
  c.width = app.add_option("--width", o.width, "Render width in pixels")->check(CLI::Range(16, 8192));
  c.height = app.add_option("--height", o.height, "Render height in pixels")->check(CLI::Range(16, 8192));
  c.exposure = app.add_option("--exposure", o.exposure,
                              "Fixed linear exposure before tonemapping, e.g. 0.3 (the demo level's look, as "
                              "its goldens); default: automatic (docs/exposure.md)")
                   ->check(CLI::PositiveNumber);
  c.ev100 = app.add_option("--ev100", o.ev100,
                           "Fixed exposure of a camera at this EV100: radiance x 683 / (1.2 x 2^EV100) "
                           "(15: the sunny-16 rule)")
                ->excludes(c.exposure);
  app.add_option("--exposure-compensation", o.exposure_compensation_ev,
                 "Automatic exposure: EV added after metering (+1: twice as bright)")
      ->excludes(c.exposure)
      ->excludes(c.ev100);
  app.add_option(
         "--area-shadows", c.area_shadows,
         "soft: area lights soft-shadowed over their rectangle (default); centre: from their centre only (cheaper)")
      ->check(CLI::IsMember({"soft", "centre"}));
  app.add_option("--light-reach", c.light_reach,
                 "on: static lights shade only where static geometry lets them reach (default); off: every light "
                 "on every pixel (engine::RenderSettings::light_reach_culling)")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--area-shadow-res", c.area_shadow_res,
                 "half: area lights' soft shadows at half resolution, upsampled on each pixel's own surface "
                 "(default); full: per pixel (engine::RenderSettings::area_shadow_res)")
      ->check(CLI::IsMember({"full", "half"}));
  app.add_option(
         "--shading", c.shading,
         "full: the frame as players see it (default); flat: measurement only, every surface its base colour "
         "unlit with everything else as usual, the cost floor of any shading (engine::RenderSettings::flat_shading)")
      ->check(CLI::IsMember({"full", "flat"}));
}

void add_session_options(CLI::App& app, RunOptions& o) {
  app.add_option("--every", o.every, "Headless: write every K-th frame")->check(CLI::PositiveNumber);
  app.add_flag("--exr", o.exr, "Headless: also write DIR/frame_NNNN.exr (linear HDR)");
  app.add_flag("--no-render", o.no_render, "Headless: simulate only (no GPU), e.g. to record sessions");
  auto* rec = app.add_option("--record", o.record_file, "Record the inputs and checksums into a .girec session");
  app.add_option("--replay", o.replay_file, "Replay a .girec session, checking every frame's checksum")->excludes(rec);
  app.add_option("--script", o.script,
                 "Headless input script: tour, walk_flashlight, push_crates, split_screen, open_door, crate_to_wall, "
                 "none (a still camera; default: tour on the demo level, none on any other --scene)");
  app.add_option("--seed", o.seed, "Session seed (recorded in the header and the checksum)");
  app.add_flag("--only-written-frames", o.only_written,
               "Headless: render only the frames --out/--every write (fast golden and approval runs)");
  app.add_option("--gi-bundle", o.gi_bundle,
                 "Light the static world with the light atlas of this bake bundle (scene.gibake/)");
  app.add_option("--sky", o.sky,
                 "Replace the scene's sky, as gi-bake --sky: R,G,B a uniform sky, or "
                 "'zenith:R,G,B;horizon:R,G,B;ground:R,G,B' a gradient (W/(m^2 sr); docs/scene-format.md)")
      ->check([](const std::string& text) {
        return engine::parse_sky_text(text) ? std::string() : std::string("--sky wants ") + engine::kSkyTextUsage;
      });
  app.add_flag("--verbose", o.verbose, "Headless: print the script's waypoints and the player's position each second");
}

// Turns the parsed choices into the run's options and checks those that exclude each other;
// the exit code when they do.
std::optional<int> settle_options(const RenderChoices& c, RunOptions& o) {
  o.area_soft_shadows = c.area_shadows == "soft";
  o.light_reach_culling = c.light_reach == "on";
  o.flat_shading = c.shading == "flat";
  o.area_shadow_res = c.area_shadow_res == "half" ? engine::AreaShadowRes::Half : engine::AreaShadowRes::Full;
  o.size_given = c.width->count() > 0 || c.height->count() > 0;
  o.exposure_mode = c.exposure->count() > 0 ? engine::ExposureMode::FixedLinear
                    : c.ev100->count() > 0  ? engine::ExposureMode::FixedEv100
                                            : engine::ExposureMode::Automatic;
  if (o.script.empty()) o.script = std::string(script_name(default_script(o.scene)));
  if (!script_from_name(o.script)) {
    return tools::fail("gi_demo", "unknown --script \"" + o.script + "\"", tools::kExitUsage);
  }
  if (o.no_render && !o.out_dir.empty()) {
    return tools::fail("gi_demo", "--no-render cannot write frames (--out)", tools::kExitUsage);
  }
  if (o.no_render && !o.gi_bundle.empty()) {
    return tools::fail("gi_demo", "--no-render does not light anything (--gi-bundle)", tools::kExitUsage);
  }
  return std::nullopt;
}

// The simulation of a replayed session (its size unless --width/--height); false after saying why not.
bool open_replay(RunOptions& o, RunState& state) {
  auto session = load_session(o.replay_file);
  if (!session) {
    std::cerr << "gi_demo: " << session.error().to_string() << '\n';
    return false;
  }
  auto sim = simulation_for_session(*session, o.replay_file,
                                    o.scene.empty() ? std::filesystem::path() : resolve_scene_path(o.scene));
  if (!sim) {
    std::cerr << "gi_demo: " << sim.error().to_string() << '\n';
    return false;
  }
  if (!o.size_given) {
    o.width = static_cast<int>(session->header.width);
    o.height = static_cast<int>(session->header.height);
  }
  state.sim = std::make_unique<Simulation>(std::move(sim).value());
  state.replay = std::move(session).value();
  return true;
}

// The simulation of a new session on the scene, with its recording's header when --record;
// false after saying why not.
bool open_new_session(const RunOptions& o, RunState& state) {
  const std::string as_given = o.scene.empty() ? std::string("assets/demo_level.gltf") : o.scene;
  const std::filesystem::path path = o.scene.empty() ? default_scene_path() : resolve_scene_path(o.scene);
  auto scene = load_scene(path);
  if (!scene) {
    std::cerr << "gi_demo: " << scene.error().to_string() << '\n';
    return false;
  }
  state.sim = std::make_unique<Simulation>(
      std::move(scene).value(),
      SimulationSettings{.seed = o.seed, .tuning = {.locomotion = default_locomotion(as_given)}});
  if (!o.record_file.empty()) {
    auto hash = hash_scene_file(path);
    if (!hash) {
      std::cerr << "gi_demo: " << hash.error().to_string() << '\n';
      return false;
    }
    Session s;
    s.header = SessionHeader{.scene_path = as_given,
                             .scene_hash = *hash,
                             .seed = o.seed,
                             .width = static_cast<std::uint32_t>(o.width),
                             .height = static_cast<std::uint32_t>(o.height),
                             .fixed_dt_s = state.sim->settings().fixed_dt_s};
    state.record = std::move(s);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  RunOptions o;
  RenderChoices choices;
  CLI::App app{"gi_demo: the playable demo level of the GI module"};
  app.add_option("--scene", o.scene, "glTF scene to play (default: assets/demo_level.gltf)");
  app.add_flag("--headless", o.headless, "Run without a window (EGL surfaceless), driven by --script or --replay");
  app.add_option("--frames", o.frames, "Fixed steps to run (headless default 120; replay: the session length)");
  app.add_option("--out", o.out_dir, "Headless: write DIR/frame_NNNN.png (tonemapped)");
  add_render_options(app, o, choices);
  add_session_options(app, o);
  // The tools' host contract (tools/common/tool_main.h): --version, exit 0 done, 1 failed,
  // 2 bad usage, 130 Ctrl-C (the recording is then not written).
  if (const std::optional<int> rc = tools::parse(app, "gi_demo", argc, argv)) return *rc;
  if (const std::optional<int> rc = settle_options(choices, o)) return *rc;

  RunState state;
  if (!(o.replay_file.empty() ? open_new_session(o, state) : open_replay(o, state))) return 1;
  if (!o.sky.empty()) {  // before the renderer and the GI system read the scene
    const engine::SkyText sky = engine::parse_sky_text(o.sky).value();  // checked by the option
    state.sim->scene().assets.environment.sky_radiance = sky.uniform;
    state.sim->scene().assets.environment.sky_gradient = sky.gradient;
  }
  tools::install_interrupt_handler();
  const int status = o.headless ? run_headless(o, state) : run_windowed(o, state);
  if (status == tools::kExitCancelled)  // no half-played session recorded
    return tools::fail("gi_demo", "cancelled (Ctrl-C), nothing recorded", tools::kExitCancelled);
  if (!state.finish_recording(o.record_file)) return tools::kExitFailure;
  if (state.replay && status == 0) {
    const std::uint64_t played = state.sim->frame();
    if (played < state.replay->frames.size()) {
      std::cout << "replay stopped after " << played << " of " << state.replay->frames.size()
                << " frames, all checksums matched\n";
    } else {
      std::cout << "replay OK: " << played << " frames, all checksums match\n";
    }
  }
  return state.mismatches > 0 ? tools::kExitFailure : status;
}
