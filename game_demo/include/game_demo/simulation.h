#pragma once
// The demo's fixed-timestep simulation: a scene, its gameplay systems and a frame counter.
// One step() consumes one InputFrame and returns the state checksum after it.
//   game_demo::Simulation sim(std::move(scene), {.fixed_dt_s = 1.0 / 60.0});
//   std::uint64_t checksum = sim.step(input);

#include <cstdint>
#include <memory>

#include <engine/scene.h>
#include <engine/system_schedule.h>

#include <game_demo/gameplay.h>
#include <game_demo/input_frame.h>

namespace game_demo {

/// The level's exposure (linear scale before tonemapping): its white rooms under multi-bounce
/// indirect light. gi_demo's default, and what the golden replays render with.
inline constexpr float kDemoExposure = 0.3f;

struct SimulationSettings {
  double fixed_dt_s = 1.0 / 60.0;  ///< Length of one step, seconds.
  std::uint64_t seed = 0;          ///< Session seed (part of the checksum).
  GameplayTuning tuning{};
};

class Simulation {
 public:
  /// Takes the scene and readies it for play (game_demo::prepare_scene).
  explicit Simulation(engine::Scene scene, const SimulationSettings& settings = {});
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  ~Simulation();

  /// Starts a new registry frame (clearing change records), runs the gameplay systems once
  /// with `input`, and returns the state checksum after the step.
  std::uint64_t step(const InputFrame& input);

  /// Checksum of the current state (the value step() returned last; frame 0 before any).
  std::uint64_t checksum() const;

  /// Steps completed so far.
  std::uint64_t frame() const;

  engine::Scene& scene();
  const engine::Scene& scene() const;
  engine::Registry& registry() { return scene().registry; }
  const engine::Registry& registry() const { return scene().registry; }
  const GameplayContext& context() const;
  const engine::SystemSchedule& schedule() const;
  const SimulationSettings& settings() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace game_demo
