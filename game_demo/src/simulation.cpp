#include <game_demo/simulation.h>

#include <game_demo/state_checksum.h>

namespace game_demo {

struct Simulation::State {
  engine::Scene scene;
  SimulationSettings settings;
  GameplayContext context;
  engine::SystemSchedule schedule;
  std::uint64_t frame = 0;
};

Simulation::Simulation(engine::Scene scene, const SimulationSettings& settings) : state_(std::make_unique<State>()) {
  GI_EXPECTS(settings.fixed_dt_s > 0.0 && settings.fixed_dt_s < 1.0, "fixed step must be in (0, 1) s");
  state_->scene = std::move(scene);
  state_->settings = settings;
  state_->context = prepare_scene(state_->scene, settings.tuning);
  add_gameplay_systems(state_->schedule, state_->context);  // keeps a pointer into *state_
}

Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;
Simulation::~Simulation() = default;

std::uint64_t Simulation::step(const InputFrame& input) {
  State& s = *state_;
  s.scene.registry.begin_frame();
  s.context.input = input;
  s.schedule.run(s.scene.registry, engine::FrameTime{.dt_s = s.settings.fixed_dt_s,
                                                     .frame = s.frame,
                                                     .time_s = static_cast<double>(s.frame) * s.settings.fixed_dt_s});
  s.context.previous_keys = input.keys;
  ++s.frame;
  return checksum();
}

std::uint64_t Simulation::checksum() const {
  const State& s = *state_;
  return state_checksum(s.scene.registry, ChecksumExtras{.frame = s.frame,
                                                         .seed = s.settings.seed,
                                                         .previous_keys = s.context.previous_keys,
                                                         .split_view = s.context.split_view});
}

std::uint64_t Simulation::frame() const { return state_->frame; }
engine::Scene& Simulation::scene() { return state_->scene; }
const engine::Scene& Simulation::scene() const { return state_->scene; }
const GameplayContext& Simulation::context() const { return state_->context; }
const engine::SystemSchedule& Simulation::schedule() const { return state_->schedule; }
const SimulationSettings& Simulation::settings() const { return state_->settings; }

}  // namespace game_demo
