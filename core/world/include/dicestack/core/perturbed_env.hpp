#pragma once
// One episode's environment as a policy meets it, the wrapper Gymnasium and robosuite put around
// an environment: the perturbation's factors drawn from the episode's seed, the world they make,
// and between the policy and that world the sensing (what the policy is shown: noisy, late) and
// the actuation (what runs: the choice clipped to the world's limits, late, biased and noised,
// plus noise the world cannot foresee, such as DART's); and, when asked, a state estimator
// between the sensors and the policy. rollout() and the Python environment step
// through it, so both give the same episodes.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>

#include <dicestack/core/env.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/types.hpp>

namespace dicestack {

/// One step through a PerturbedEnv.
struct PerturbedStep {
  StepResult result;  ///< the world's step; result.observation is the true state
  State shown;        ///< what the policy is shown of it
};

class PerturbedEnv {
 public:
  /// The episode of `episode_seed` under `perturbation` (draw_perturbation): it runs in `pooled`
  /// when the draw leaves the physics nominal, else in a world of its own. `pooled` must outlive
  /// it. `actions`: the kind the policy answers in (its delay, noise and bias are of that kind).
  PerturbedEnv(DiceEnv& pooled, const Perturbation& perturbation, std::uint64_t episode_seed,
               ActionKind actions = ActionKind::cup);
  /// The same for a draw already made (a replay, a test's own draw).
  PerturbedEnv(DiceEnv& pooled, const PerturbationDraw& draw, ActionKind actions = ActionKind::cup);
  /// `env` unperturbed.
  explicit PerturbedEnv(DiceEnv& env);
  PerturbedEnv(const PerturbedEnv&) = delete;  // env_ may point into own_
  PerturbedEnv& operator=(const PerturbedEnv&) = delete;

  /// Adds N(0, sigma[k]) world units to each executed action, after the perturbation's bias and
  /// noise, from its own stream `seed`: outside the world, so an expert that simulates cannot
  /// foresee it (DART's noise). All zero: none.
  void add_executed_noise(const Action& sigma, std::uint64_t seed);

  /// Shows the policy `config`'s estimate of the state instead of the raw observation, from the
  /// next reset on; without sensing factors in the draw the policy sees the state and nothing
  /// changes. Its model is the nominal world (the pooled one).
  void use_estimator(const EstimatorConfig& config);

  /// The random start of the episode of `episode_seed` in the drawn world (its start ranges).
  State random_start(std::uint64_t episode_seed) const;
  /// Starts the episode at `start`, the world's own physics noise seeded by `seed`; returns what
  /// the policy is shown of it.
  State reset_to(const State& start, std::uint64_t seed);
  /// Starts the episode as DiceEnv::reset(seed) does, in the drawn world; returns what the policy
  /// is shown of it.
  State reset(std::uint64_t seed);
  /// One control step from what the policy chose.
  PerturbedStep step(const Action& chosen);
  /// `a` within the world's action limits: what step() runs before any delay or noise.
  Action clip(const Action& a) const;

  DiceEnv& env() { return *env_; }
  const DiceEnv& env() const { return *env_; }
  const PerturbationDraw& draw() const { return draw_; }
  /// True when the physics, the actuation or the sensing differs from the nominal world's.
  bool perturbed() const { return draw_.physics || draw_.acts; }
  /// True when the actuation or sensing is perturbed: what the policy is shown is not the state.
  bool channelled() const { return channel_.has_value(); }
  /// The arm's links the policy is shown with what it is shown: for a policy in joint torques
  /// behind an estimator, the estimator's (those of the state its estimate stands for), else the
  /// encoders' (exact and at once).
  ArmLinks shown_links() const {
    return estimator_ && actions_ == ActionKind::joint_torque ? estimator_->links() : env_->world().arm_links();
  }
  /// What runs before the next choice under an action delay (History::pending). Empty without,
  /// and with an estimator: its estimate is of the state the next choice lands in.
  const std::deque<Action>& pending() const;
  /// What ran since the state last shown, under an observation delay (History::unseen). Empty
  /// without, and with an estimator: its estimate is of the current state.
  const std::deque<Action>& unseen() const;

 private:
  void read_encoders();  // an arm's links, exact and at once, to a torque policy's estimator

  PerturbationDraw draw_;
  std::optional<DiceEnv> own_;  // the world of a draw whose physics differs
  DiceEnv* env_;
  const WorldConfig* model_;  // the nominal world, an estimator's model
  ActionKind actions_ = ActionKind::cup;  // what the policy answers in
  std::optional<PerturbedChannel> channel_;
  EstimatorConfig estimator_config_;
  std::unique_ptr<Estimator> estimator_;  // made at each reset from estimator_config_
  Action executed_noise_{0.0, 0.0, 0.0};
  bool noisy_ = false;
  Rng noise_{0};
  std::deque<Action> none_;  // pending() and unseen() without a channel

  State first_shown(const State& start);
};

}  // namespace dicestack
