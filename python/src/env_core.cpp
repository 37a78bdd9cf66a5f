#include "env_core.hpp"

#include <algorithm>
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

EnvCore::EnvCore(const WorldConfig& world, const Perturbation& perturbation)
    : world_(world),
      perturbation_(perturbation),
      env_(std::make_unique<DiceEnv>(world)),
      goal_(goal_state(world)),
      nominal_hash_(dicestack::world_hash(world)),
      world_hash_(nominal_hash_),
      draw_(draw_perturbation(Perturbation{}, world, 0)) {
  validate(perturbation, world);
}

void EnvCore::begin(const Perturbation* perturbation) {
  const Perturbation& p = perturbation ? *perturbation : perturbation_;
  const bool was_perturbed = draw_.physics;
  draw_ = draw_perturbation(p, world_, episode_seed_);
  if (draw_.physics || was_perturbed) {
    env_ = std::make_unique<DiceEnv>(draw_.world);
    world_hash_ = draw_.physics ? dicestack::world_hash(draw_.world) : nominal_hash_;
  }
  channel_.reset();
  if (draw_.acts) channel_.emplace(draw_);
}

State EnvCore::reset(std::optional<std::uint64_t> seed, const Perturbation* perturbation) {
  if (perturbation) validate(*perturbation, world_);  // before the episode counts
  episode_seed_ = seeds_.next(seed);
  ++episodes_;
  begin(perturbation);
  return observed(env_->reset(episode_seed_));
}

State EnvCore::reset_to(const State& state, std::optional<std::uint64_t> seed, const Perturbation* perturbation) {
  check_state_in_world(state, world_, "reset state");
  if (perturbation) validate(*perturbation, world_);
  episode_seed_ = seeds_.next(seed);
  ++episodes_;
  begin(perturbation);
  return observed(env_->reset_to(state, episode_seed_));
}

StepResult EnvCore::step(const Action& action) {
  if (episodes_ == 0) throw std::logic_error("Cannot call step() before calling reset()");
  if (!channel_) return env_->step(action);
  // As rollout() does: the choice clipped to the limits, then delayed, biased and noised.
  Action chosen = action;
  const auto& limit = env_->config().action.limit;
  for (std::size_t k = 0; k < kActionDim; ++k) chosen[k] = std::clamp(chosen[k], -limit[k], limit[k]);
  StepResult r = env_->step(channel_->execute(chosen));
  r.observation = channel_->observe(r.observation);
  return r;
}

StepInfo EnvCore::info() const {
  StepInfo i;
  i.t = env_->t();
  i.distance = state_distance(env_->get_state(), goal_, env_->config().cost);
  i.outcome = env_->outcome();
  return i;
}

void EnvCore::restored(std::uint64_t episode_seed) {
  episode_seed_ = episode_seed;
  ++episodes_;  // a restored episode is a new one for an expert acting here
}

}  // namespace dicestack::python
