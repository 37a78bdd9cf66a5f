#pragma once
// One environment as the Python package steps it: a DiceEnv plus Gymnasium's seeding rule, shared
// by DiceStackEnv and every slot of DiceStackVectorEnv so that both give the same episodes.
// Plain C++ (no Python types), so the vector env can step it with the GIL released.
#include <cstdint>
#include <optional>

#include <memory>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/core/perturbed_env.hpp>

namespace dicestack::python {

/// Episode seeds under Gymnasium's rule: reset(seed=s) starts from s; a reset without a seed takes
/// the next seed of a stream derived from the last explicit seed (derive_seed(s, 1), (s, 2), ...),
/// or from the operating system's entropy when no seed was ever given.
class EpisodeSeeds {
 public:
  std::uint64_t next(std::optional<std::uint64_t> seed);

  /// The stream's state, for snapshots: the last explicit seed (if any) and resets since.
  std::optional<std::uint64_t> base() const { return base_; }
  std::uint64_t count() const { return count_; }
  void set(std::optional<std::uint64_t> base, std::uint64_t count) { base_ = base, count_ = count; }

 private:
  std::optional<std::uint64_t> base_;
  std::uint64_t count_ = 0;
};

/// A DiceEnv with its seed stream and what the Python info dict reports. Each episode steps
/// through a PerturbedEnv, as rollout() does: under a perturbation it runs in the world drawn from
/// its seed, and its observations and actions pass through the draw's sensing and actuation; the
/// same episodes as C++.
class EnvCore {
 public:
  /// `estimator`: what the policy is shown under sensing factors (estimator.hpp); `controller`:
  /// what an action is (the cup's velocity change, or an arm's joint torques). Throws
  /// ConfigError for joint torques without the arm, or behind the particle filter (its worlds
  /// hold no arm links).
  explicit EnvCore(const WorldConfig& world, const Perturbation& perturbation = {}, const EstimatorConfig& estimator = {},
                   ActionKind controller = ActionKind::cup);
  ActionKind controller() const { return controller_; }

  /// Starts an episode from random_start_state(world, seed), `seed` per EpisodeSeeds, under
  /// `perturbation` if given (this episode only), else the environment's own.
  State reset(std::optional<std::uint64_t> seed, const Perturbation* perturbation = nullptr);
  /// Starts an episode from a bare state; `seed` (per EpisodeSeeds) seeds the action noise.
  State reset_to(const State& state, std::optional<std::uint64_t> seed, const Perturbation* perturbation = nullptr);
  /// One control step. Throws std::logic_error before the first reset (Gymnasium's order).
  StepResult step(const Action& action);
  /// What the current episode drew (nominal: the world unchanged, nothing else).
  const PerturbationDraw& draw() const { return episode_ ? episode_->draw() : nominal_draw_; }
  /// True when the current episode's actuation or sensing is perturbed (its delays and noise
  /// stream are not in a snapshot).
  bool channelled() const { return episode_ && episode_->channelled(); }
  /// What runs before the next action under the episode's action delay (History::pending):
  /// an expert acting here simulates through it. Empty without a delay.
  std::vector<Action> pending() const {
    return episode_ ? std::vector<Action>(episode_->pending().begin(), episode_->pending().end()) : std::vector<Action>{};
  }
  /// What ran since the state the last observation showed, under an observation delay
  /// (History::unseen). Empty without a delay.
  std::vector<Action> unseen() const {
    return episode_ ? std::vector<Action>(episode_->unseen().begin(), episode_->unseen().end()) : std::vector<Action>{};
  }

  /// The info of the episode's latest state (what reset reports; step's own is in StepResult).
  StepInfo info() const;

  /// The arm's links the policy is shown: the estimator's (of the state it estimates) when one
  /// runs, else the encoders'.
  ArmLinks shown_links() const { return episode_ ? episode_->shown_links() : nominal_->world().arm_links(); }
  DiceEnv& env() { return episode_ ? episode_->env() : *nominal_; }
  const DiceEnv& env() const { return episode_ ? episode_->env() : *nominal_; }
  std::uint64_t world_hash() const { return world_hash_; }
  /// The seed of the current episode (0 before the first reset).
  std::uint64_t episode_seed() const { return episode_seed_; }
  /// Episodes started so far: an expert acting here restarts when this changes.
  std::uint64_t episodes() const { return episodes_; }
  EpisodeSeeds& seeds() { return seeds_; }

  /// Puts back a snapshot's episode bookkeeping beside DiceEnv::restore.
  void restored(std::uint64_t episode_seed);

 private:
  // Draws the new episode's perturbation and makes its world.
  void begin(const Perturbation* perturbation);

  WorldConfig world_;  // the nominal world
  Perturbation perturbation_;
  EstimatorConfig estimator_;
  ActionKind controller_;
  std::unique_ptr<DiceEnv> nominal_;  // the world of every episode whose physics is nominal
  std::unique_ptr<PerturbedEnv> episode_;  // the current episode (null before the first reset)
  State goal_;
  std::uint64_t nominal_hash_, world_hash_;
  PerturbationDraw nominal_draw_;  // draw() before the first reset
  EpisodeSeeds seeds_;
  std::uint64_t episode_seed_ = 0;
  std::uint64_t episodes_ = 0;
};

}  // namespace dicestack::python
