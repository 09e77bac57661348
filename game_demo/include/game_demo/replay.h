#pragma once
// Replaying recorded sessions: load the scene a session names (checking it is the very
// scene it was recorded on), feed the recorded inputs, compare checksums frame by frame.
//   auto session = game_demo::load_session("tests/sessions/walk_flashlight.girec");
//   auto sim = game_demo::simulation_for_session(*session, "tests/sessions/walk_flashlight.girec");
//   game_demo::ReplayOutcome out = game_demo::replay_inputs(*sim, *session);

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include <engine/result.h>
#include <engine/scene.h>

#include <game_demo/session_file.h>
#include <game_demo/simulation.h>

namespace game_demo {

/// Resolves a scene path as given by the user or a session header: as is when it exists,
/// else relative to the project's source directory (where assets/ lives).
std::filesystem::path resolve_scene_path(const std::filesystem::path& as_given);

/// The demo level, assets/demo_level.gltf in the source directory.
std::filesystem::path default_scene_path();

/// Loads a glTF scene and instantiates it; the loader's error on a bad file.
engine::Result<engine::Scene> load_scene(const std::filesystem::path& path);

/// Loads the scene of `session` (or `scene_override` when not empty), checks its hash
/// against the header and builds a Simulation with the session's step and seed. A changed
/// scene is an Error naming `session_file` and telling how to re-record.
engine::Result<Simulation> simulation_for_session(const Session& session, const std::string& session_file,
                                                  const std::filesystem::path& scene_override = {});

struct ReplayMismatch {
  std::uint64_t frame = 0;     ///< 0-based step index of the first differing checksum.
  std::uint64_t recorded = 0;  ///< Checksum stored in the session.
  std::uint64_t replayed = 0;  ///< Checksum recomputed now.
};

struct ReplayOutcome {
  std::uint64_t frames_replayed = 0;
  std::optional<ReplayMismatch> mismatch;  ///< The first mismatch; replay stops there.
};

/// Called after each replayed step with the step's 0-based index.
using ReplayFrameCallback = std::function<void(Simulation&, std::uint64_t frame)>;

/// Feeds every recorded input to `sim` (which must be fresh) and compares checksums.
ReplayOutcome replay_inputs(Simulation& sim, const Session& session, const ReplayFrameCallback& after_step = {});

/// "frame 17: recorded checksum 0x..., replayed 0x..." for messages.
std::string describe(const ReplayMismatch& m);

}  // namespace game_demo
