#include "env_core.hpp"

#include <random>
#include <stdexcept>

#include <dicestack/core/cost.hpp>
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

EnvCore::EnvCore(const WorldConfig& world)
    : env_(world), goal_(goal_state(world)), world_hash_(dicestack::world_hash(world)) {}

State EnvCore::reset(std::optional<std::uint64_t> seed) {
  episode_seed_ = seeds_.next(seed);
  ++episodes_;
  return env_.reset(episode_seed_);
}

State EnvCore::reset_to(const State& state, std::optional<std::uint64_t> seed) {
  require_finite(state, "reset state");
  episode_seed_ = seeds_.next(seed);
  ++episodes_;
  return env_.reset_to(state, episode_seed_);
}

StepResult EnvCore::step(const Action& action) {
  if (episodes_ == 0) throw std::logic_error("Cannot call step() before calling reset()");
  return env_.step(action);
}

StepInfo EnvCore::info() const {
  StepInfo i;
  i.t = env_.t();
  i.distance = state_distance(env_.get_state(), goal_, env_.config().cost);
  i.outcome = env_.outcome();
  return i;
}

void EnvCore::restored(std::uint64_t episode_seed) {
  episode_seed_ = episode_seed;
  ++episodes_;  // a restored episode is a new one for an expert acting here
}

}  // namespace dicestack::python
