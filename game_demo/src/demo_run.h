#pragma once
// The gi_demo executable's shared pieces: its options, the session being recorded or
// replayed, and the two front ends (headless and windowed). Not part of gi_demo_lib.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <engine/indirect_light.h>
#include <engine/renderer.h>
#include <gi/gi_system.h>

#include <game_demo/replay.h>
#include <game_demo/scripted_pilot.h>
#include <game_demo/session_file.h>
#include <game_demo/simulation.h>

namespace game_demo {

struct RunOptions {
  std::string scene;  ///< As given (empty: the demo level).
  bool headless = false;
  std::uint64_t frames = 0;  ///< 0: headless default 120 / replay length / windowed unlimited.
  std::string out_dir;       ///< Headless frame folder (empty: no images written).
  int width = 960;
  int height = 540;
  /// Exposure (engine/exposure.h, docs/exposure.md): automatic unless --exposure (a fixed
  /// linear scale, as the goldens render with kDemoExposure) or --ev100 fixes it.
  engine::ExposureMode exposure_mode = engine::ExposureMode::Automatic;
  float exposure = kDemoExposure;         ///< --exposure: linear scale before tonemapping.
  float ev100 = 15.0f;                    ///< --ev100: a camera's exposure value at ISO 100.
  float exposure_compensation_ev = 0.0f;  ///< --exposure-compensation: automatic exposure's bias, EV.
  bool area_soft_shadows = true;          ///< --area-shadows soft|centre (engine::RenderSettings::area_soft_shadows).
  bool light_reach_culling = true;        ///< --light-reach on|off (engine::RenderSettings::light_reach_culling).
  bool flat_shading = false;              ///< --shading full|flat (engine::RenderSettings::flat_shading: a yardstick).
  /// --area-shadow-res full|half (engine::RenderSettings::area_shadow_res).
  engine::AreaShadowRes area_shadow_res = engine::AreaShadowRes::Half;
  bool size_given = false;
  std::uint64_t every = 1;
  bool exr = false;
  bool no_render = false;
  std::string record_file;
  std::string replay_file;
  std::string script;  ///< Empty: "tour" on the demo level, "none" (a still camera) on any other scene.
  std::uint64_t seed = 0;
  bool verbose = false;
  bool only_written = false;  ///< Headless: render only the frames written to --out.
  std::string gi_bundle;      ///< Bake bundle (scene.gibake/) whose light atlas lights the scene; empty: stand-in.
  std::string sky;  ///< --sky: the sky replacing the scene's (engine::parse_sky_text; empty: the scene's own).
};

/// Everything a run needs after start-up checks: the simulation, and the session being
/// replayed (loaded) or recorded (filled in as steps run).
struct RunState {
  std::unique_ptr<Simulation> sim;
  std::optional<Session> replay;  ///< Set with --replay.
  std::optional<Session> record;  ///< Set with --record; frames appended by record_step().
  std::uint64_t mismatches = 0;

  /// Steps the simulation with `input`, appends to the recording, checks the replay.
  /// Returns false (after printing the mismatch) when a replayed checksum differs.
  bool step(const InputFrame& input);
  /// Writes the recording, if any; prints and returns false on failure.
  bool finish_recording(const std::string& path) const;
};

/// The renderer's settings for a run (size, exposure, shadows, light reach, shading).
engine::RenderSettings render_settings(const RunOptions& options);

/// One line for the overlay and the headless summary: the exposure of the last frame
/// ("automatic, EV100 12.31 (target 12.40) ..."; reads it back from the GPU when automatic).
std::string describe_exposure(const RunOptions& options, const engine::Renderer& renderer);

/// The game time since the previous render, for automatic exposure's adaptation: the
/// steps run since then x the fixed step (0 when none ran; the first frame snaps anyway).
struct RenderClock {
  std::uint64_t last_rendered_step = 0;
  double dt_s(const Simulation& sim) {
    const double dt = static_cast<double>(sim.frame() - last_rendered_step) * sim.settings().fixed_dt_s;
    last_rendered_step = sim.frame();
    return dt;
  }
};

/// Maps the simulation's split flag to the renderer's setting.
inline engine::SplitView split_of(const Simulation& sim) {
  return sim.context().split_view ? engine::SplitView::DirectLeftFullRight : engine::SplitView::Off;
}

/// The indirect light of a run: with --gi-bundle, the GI system of the bundle (light atlas,
/// PRM for the moving lights, basis radiance fields for the crates; gi::GISystem) loaded
/// against the simulation's scene (which it leaves as it is: the atlas UVs reach the renderer
/// through the provider's atlas meshes, so the renderer may come before or after); without it, nullptr (the renderer's
/// constant-ambient stand-in). Prints the error and returns false when the bundle does not load (missing, damaged, or
/// baked from other geometry). Call with the GL context current; destroy the system before the context.
bool load_indirect_light(const RunOptions& options, Simulation& sim, std::unique_ptr<gi::GISystem>& system);

/// One line for stdout and the overlay: which indirect light is used.
std::string describe_indirect_light(const RunOptions& options, const gi::GISystem* system);

/// The GI system's per-method lines and counters for the overlay and the headless summary
/// (what runs and why, frames re-lit, idle frames, last update times). Empty without GI.
std::vector<std::string> gi_status_lines(const gi::GISystem* system);

int run_headless(const RunOptions& options, RunState& state);
int run_windowed(const RunOptions& options, RunState& state);

}  // namespace game_demo
