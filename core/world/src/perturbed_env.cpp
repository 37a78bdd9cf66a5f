#include <dicestack/core/perturbed_env.hpp>

#include <algorithm>

#include <dicestack/core/initial_state.hpp>

namespace dicestack {

PerturbedEnv::PerturbedEnv(DiceEnv& pooled, const Perturbation& perturbation, std::uint64_t episode_seed)
    : PerturbedEnv(pooled, draw_perturbation(perturbation, pooled.config(), episode_seed)) {}

PerturbedEnv::PerturbedEnv(DiceEnv& pooled, const PerturbationDraw& draw)
    : draw_(draw), env_(&pooled), model_(&pooled.config()) {
  if (draw_.physics) env_ = &own_.emplace(draw_.world);
  if (draw_.acts) channel_.emplace(draw_);
}

PerturbedEnv::PerturbedEnv(DiceEnv& env) : env_(&env), model_(&env.config()) { draw_.world = env.config(); }

void PerturbedEnv::use_estimator(const EstimatorConfig& config) { estimator_config_ = config; }

State PerturbedEnv::first_shown(const State& start) {
  const State observed = channel_ ? channel_->observe(start) : start;
  estimator_ = make_estimator(estimator_config_, *model_, draw_);
  return estimator_ ? estimator_->start(observed) : observed;
}

void PerturbedEnv::add_executed_noise(const Action& sigma, std::uint64_t seed) {
  executed_noise_ = sigma;
  noisy_ = sigma[0] > 0.0 || sigma[1] > 0.0 || sigma[2] > 0.0;
  noise_ = Rng(seed);
}

State PerturbedEnv::random_start(std::uint64_t episode_seed) const {
  return random_start_state(draw_.world, episode_seed);
}

State PerturbedEnv::reset_to(const State& start, std::uint64_t seed) { return first_shown(env_->reset_to(start, seed)); }

State PerturbedEnv::reset(std::uint64_t seed) { return first_shown(env_->reset(seed)); }

Action PerturbedEnv::clip(const Action& a) const {
  const auto& limit = env_->config().action.limit;
  Action c = a;
  for (std::size_t k = 0; k < kActionDim; ++k) c[k] = std::clamp(c[k], -limit[k], limit[k]);
  return c;
}

PerturbedStep PerturbedEnv::step(const Action& chosen) {
  const Action clipped = clip(chosen);
  Action executed = channel_ ? channel_->execute(clipped) : clipped;
  if (noisy_)
    for (std::size_t k = 0; k < kActionDim; ++k) executed[k] += executed_noise_[k] * noise_.normal();
  PerturbedStep s{env_->step(executed), {}};
  s.shown = channel_ ? channel_->observe(s.result.observation) : s.result.observation;
  if (estimator_) s.shown = estimator_->update(clipped, s.shown);
  return s;
}

const std::deque<Action>& PerturbedEnv::pending() const {
  return channel_ && !estimator_ ? channel_->pending() : none_;
}

const std::deque<Action>& PerturbedEnv::unseen() const {
  return channel_ && !estimator_ ? channel_->unseen() : none_;
}

}  // namespace dicestack
