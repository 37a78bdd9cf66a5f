#include <dicestack/core/perturbed_env.hpp>

#include <algorithm>
#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>

namespace dicestack {

PerturbedEnv::PerturbedEnv(DiceEnv& pooled, const Perturbation& perturbation, std::uint64_t episode_seed, ActionKind actions)
    : PerturbedEnv(pooled, draw_perturbation(perturbation, pooled.config(), episode_seed), actions) {}

PerturbedEnv::PerturbedEnv(DiceEnv& pooled, const PerturbationDraw& draw, ActionKind actions)
    : draw_(draw), env_(&pooled), model_(&pooled.config()), actions_(actions) {
  if (draw_.physics) env_ = &own_.emplace(draw_.world);
  if (draw_.acts) channel_.emplace(draw_, actions);
}

PerturbedEnv::PerturbedEnv(DiceEnv& env) : env_(&env), model_(&env.config()) { draw_.world = env.config(); }

void PerturbedEnv::use_estimator(const EstimatorConfig& config) { estimator_config_ = config; }

State PerturbedEnv::first_shown(const State& start) {
  const State observed = channel_ ? channel_->observe(start) : start;
  estimator_ = make_estimator(estimator_config_, *model_, draw_, actions_);
  if (!estimator_) return observed;
  read_encoders();
  return estimator_->start(observed);
}

void PerturbedEnv::add_executed_noise(const Action& sigma, std::uint64_t seed) {
  executed_noise_ = sigma;
  noisy_ = std::any_of(sigma.begin(), sigma.end(), [](double x) { return x > 0.0; });
  noise_ = Rng(seed);
}

State PerturbedEnv::random_start(std::uint64_t episode_seed) const {
  return random_start_state(draw_.world, episode_seed);
}

State PerturbedEnv::reset_to(const State& start, std::uint64_t seed) { return first_shown(env_->reset_to(start, seed)); }

State PerturbedEnv::reset(std::uint64_t seed) { return first_shown(env_->reset(seed)); }

Action PerturbedEnv::clip(const Action& a) const { return clipped(env_->config(), a); }

PerturbedStep PerturbedEnv::step(const Action& chosen) {
  const Action clipped = clip(chosen);
  Action executed = channel_ ? channel_->execute(clipped) : clipped;
  if (noisy_) {
    if (executed.kind() != executed_noise_.kind())
      throw InputError("the executed noise is for " + std::string(action_kind_name(executed_noise_.kind())) +
                       " actions, the action is for the " + std::string(action_kind_name(executed.kind())) + " controller");
    for (std::size_t k = 0; k < executed.size(); ++k) executed[k] += executed_noise_[k] * noise_.normal();
  }
  PerturbedStep s{env_->step(executed), {}};
  s.shown = channel_ ? channel_->observe(s.result.observation) : s.result.observation;
  if (estimator_) {
    read_encoders();
    s.shown = estimator_->update(clipped, s.shown);
  }
  return s;
}

void PerturbedEnv::read_encoders() {
  if (actions_ == ActionKind::joint_torque) estimator_->read_encoders(env_->world().arm_links());
}

const std::deque<Action>& PerturbedEnv::pending() const {
  return channel_ && !estimator_ ? channel_->pending() : none_;
}

const std::deque<Action>& PerturbedEnv::unseen() const {
  return channel_ && !estimator_ ? channel_->unseen() : none_;
}

}  // namespace dicestack
