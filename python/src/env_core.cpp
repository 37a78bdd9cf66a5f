#include "env_core.hpp"

#include <random>
#include <stdexcept>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack::python {

std::uint64_t EpisodeSeeds::next(std::optional<std::uint64_t> seed) {
  if (seed) {
    base_ = *seed;
    count_ = 0;
    return *seed;
  }
  if (!base_) {
    std::random_device entropy;
    base_ = (std::uint64_t{entropy()} << 32) ^ entropy();
    count_ = 0;
  }
  return derive_seed(*base_, ++count_);
}

EnvCore::EnvCore(const WorldConfig& world, const Perturbation& perturbation, const EstimatorConfig& estimator,
                 ActionKind controller)
    : world_(world),
      perturbation_(perturbation),
      estimator_(estimator),
      controller_(controller),
      nominal_(std::make_unique<DiceEnv>(world)),
      goal_(goal_state(world)),
      nominal_hash_(dicestack::world_hash(world)),
      world_hash_(nominal_hash_),
      nominal_draw_(draw_perturbation(Perturbation{}, world, 0)) {
  validate(perturbation, world);
  if (controller == ActionKind::joint_torque && world.embodiment != Embodiment::arm)
    throw ConfigError("controller \"joint_torque\" drives an arm's joints: it needs embodiment \"arm\"");
  if (controller == ActionKind::joint_torque && estimator.kind == EstimatorKind::particle)
    throw ConfigError("the particle filter rebuilds its worlds without the arm's links; the joint_torque controller runs "
                      "behind estimator \"kalman\" or none");
}

void EnvCore::begin(const Perturbation* perturbation) {
  episode_ = std::make_unique<PerturbedEnv>(*nominal_, perturbation ? *perturbation : perturbation_, episode_seed_, controller_);
  episode_->use_estimator(estimator_);
  world_hash_ = episode_->draw().physics ? dicestack::world_hash(episode_->draw().world) : nominal_hash_;
}

State EnvCore::reset(std::optional<std::uint64_t> seed, const Perturbation* perturbation) {
  if (perturbation) validate(*perturbation, world_);  // before the episode counts
  episode_seed_ = seeds_.next(seed);
  ++episodes_;
  begin(perturbation);
  return episode_->reset(episode_seed_);
}

State EnvCore::reset_to(const State& state, std::optional<std::uint64_t> seed, const Perturbation* perturbation) {
  check_state_in_world(state, world_, "reset state");
  if (perturbation) validate(*perturbation, world_);
  episode_seed_ = seeds_.next(seed);
  ++episodes_;
  begin(perturbation);
  return episode_->reset_to(state, episode_seed_);
}

StepResult EnvCore::step(const Action& action) {
  if (episodes_ == 0) throw std::logic_error("Cannot call step() before calling reset()");
  PerturbedStep s = episode_->step(action);
  s.result.observation = s.shown;
  return s.result;
}

StepInfo EnvCore::info() const {
  StepInfo i;
  const DiceEnv& e = env();
  i.t = e.t();
  i.distance = state_distance(e.get_state(), goal_, e.config().cost);
  i.outcome = e.outcome();
  return i;
}

void EnvCore::restored(std::uint64_t episode_seed) {
  episode_seed_ = episode_seed;
  if (!episode_) episode_ = std::make_unique<PerturbedEnv>(*nominal_);  // restored before any reset
  ++episodes_;  // a restored episode is a new one for an expert acting here
}

}  // namespace dicestack::python
