#include <game_demo/replay.h>

#include <cstdio>
#include <system_error>

#include <engine/gltf.h>

#ifndef GI_DEMO_SOURCE_DIR
#error "GI_DEMO_SOURCE_DIR must name the project's source directory"
#endif

namespace game_demo {

namespace {
std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}
}  // namespace

std::filesystem::path resolve_scene_path(const std::filesystem::path& as_given) {
  std::error_code ec;
  if (as_given.is_absolute() || std::filesystem::exists(as_given, ec)) return as_given;
  const std::filesystem::path in_source = std::filesystem::path(GI_DEMO_SOURCE_DIR) / as_given;
  if (std::filesystem::exists(in_source, ec)) return in_source;
  return as_given;
}

std::filesystem::path default_scene_path() {
  return std::filesystem::path(GI_DEMO_SOURCE_DIR) / "assets" / "demo_level.gltf";
}

engine::Result<engine::Scene> load_scene(const std::filesystem::path& path) {
  engine::Result<engine::SceneAsset> asset = engine::load_gltf(path);
  if (!asset) return asset.error();
  return engine::instantiate(std::move(asset).value());
}

engine::Result<Simulation> simulation_for_session(const Session& session, const std::string& session_file,
                                                  const std::filesystem::path& scene_override) {
  const std::filesystem::path scene_path =
      scene_override.empty() ? resolve_scene_path(session.header.scene_path) : scene_override;
  engine::Result<std::uint64_t> hash = hash_scene_file(scene_path);
  if (!hash)
    return engine::Error{
        session_file, "header",
        "cannot read the recorded scene \"" + session.header.scene_path + "\": " + hash.error().to_string()};
  if (*hash != session.header.scene_hash)
    return engine::Error{session_file, "header",
                         "scene \"" + scene_path.string() +
                             "\" differs from the one this session was recorded on "
                             "(scene hash " +
                             hex(*hash) + ", recorded " + hex(session.header.scene_hash) +
                             "); re-record the session (tools/record-sessions.sh for the committed ones)"};
  engine::Result<engine::Scene> scene = load_scene(scene_path);
  if (!scene) return scene.error();
  return Simulation(std::move(scene).value(),
                    SimulationSettings{.fixed_dt_s = session.header.fixed_dt_s,
                                       .seed = session.header.seed,
                                       .tuning = {.locomotion = default_locomotion(session.header.scene_path)}});
}

ReplayOutcome replay_inputs(Simulation& sim, const Session& session, const ReplayFrameCallback& after_step) {
  GI_EXPECTS(sim.frame() == 0, "replay needs a fresh simulation");
  ReplayOutcome out;
  for (std::size_t i = 0; i < session.frames.size(); ++i) {
    const std::uint64_t sum = sim.step(session.frames[i].input);
    ++out.frames_replayed;
    if (after_step) after_step(sim, i);
    if (sum != session.frames[i].checksum) {
      out.mismatch = ReplayMismatch{i, session.frames[i].checksum, sum};
      break;
    }
  }
  return out;
}

std::string describe(const ReplayMismatch& m) {
  return "frame " + std::to_string(m.frame) + ": recorded checksum " + hex(m.recorded) + ", replayed " +
         hex(m.replayed);
}

}  // namespace game_demo
