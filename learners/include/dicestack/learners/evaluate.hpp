#pragma once
// Rolling policies out and measuring what they achieve (DESIGN "evaluate").
#include <functional>
#include <memory>
#include <optional>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/env.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/core/perturbed_env.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/policy.hpp>

namespace dicestack {

/// The paper's jump-start (VI-B): an extra push of the cup at the first step.
enum class InitialPush { none, left, right };

/// Parses "none", "left" or "right"; throws ConfigError otherwise.
InitialPush initial_push_from(std::string_view text);

/// How a rollout runs beyond its world (the world's perturbation and executed-action noise are
/// the PerturbedEnv's).
struct RolloutOptions {
  InitialPush push = InitialPush::none;  ///< the paper's jump-start at the first step
  /// Stop after this many steps (0: at the world's time limit or success).
  std::size_t max_steps = 0;
  /// Called before each step's action is chosen, with the environment and the step index
  /// (DaD snapshots the world there). May be empty.
  std::function<void(const DiceEnv&, std::size_t)> before_step;
};

/// The one rollout loop. Runs `policy` in `world` from `start` until termination, the time limit
/// or options.max_steps, and records the episode: the true state before each action, the
/// outcome, and per step the policy's label() if it has one, else its action clipped to the
/// world's limits (its clean label; without perturbation or noise, exactly what the world
/// applied), tagged `source`, and (format v2) the final state, each step's reward and whether it
/// ended in success (terminated) or otherwise (truncated); under a perturbation, what the episode
/// drew. The policy's History holds what it was shown (world.channelled(): noisy or late states,
/// with the pending and unseen actions) and the actions the world applied. `seed` seeds the
/// world's own physics noise.
Episode rollout(PerturbedEnv& world, Policy& policy, const State& start, std::uint64_t seed, StepSource source,
                const RolloutOptions& options = {});
/// The same in `env`, unperturbed.
Episode rollout(DiceEnv& env, Policy& policy, const State& start, std::uint64_t seed, StepSource source,
                const RolloutOptions& options = {});

/// A proportion with its 95% Wilson score interval.
struct Rate {
  double value = 0.0;
  double low = 0.0;
  double high = 0.0;
};
Rate wilson(int successes, int trials);

/// What N rollouts achieved.
struct EvalStats {
  int episodes = 0;
  double dice_in_cup_mean = 0.0;  ///< mean over episodes of the most dice held at once
  Rate dice_in_cup_3;             ///< episodes that held all three dice at some point
  Rate stacked;
  Rate wall_contact;
  Rate realistic_success;
  double mean_length = 0.0;       ///< control steps per episode
  double policy_us_per_step = 0.0;  ///< time inside the policy per control step
  double seconds = 0.0;           ///< wall time of the whole evaluation
};

/// Rollout outcomes as counts (k of n), as tables and Wilson intervals take them.
struct OutcomeCounts {
  int episodes = 0, stacked = 0, wall_contact = 0, realistic_success = 0;
};
OutcomeCounts outcome_counts(const EvalStats& stats);

/// One rollout of an evaluation, in the shape of the per-episode entries of LeRobot's
/// eval_info.json (episode index, seed, success, reward), with the judge's details.
struct EpisodeResult {
  int index = 0;               ///< the rollout's place in the evaluation
  std::uint64_t seed = 0;      ///< its start: evaluation_start_seed(request seed, index)
  bool success = false;        ///< realistic success: stacked, no wall touched
  bool stacked = false;
  bool wall_contact = false;
  int dice_in_cup = 0;         ///< most dice held at once
  int wall_step = -1;          ///< the step (0-based action) of the first wall contact; -1: none
  int length = 0;              ///< control steps
  double reward = 0.0;         ///< the environment's rewards summed
};

/// Makes one policy per worker thread (policies may keep per-episode state).
using PolicyFactory = std::function<std::unique_ptr<Policy>()>;

/// Called as each rollout ends with (rollouts finished, rollouts in all), from the worker threads,
/// several at once. An exception it throws stops the evaluation and is rethrown.
using RolloutProgress = std::function<void(int finished, int total)>;

/// What an evaluation runs: the shape of a training request, so that a new perturbation is one
/// field.
struct EvalRequest {
  int episodes = 100;
  std::uint64_t seed = 0;  ///< starts: evaluation_start_seed(seed, i)
  int threads = 0;         ///< 0: every core
  InitialPush push = InitialPush::none;
  /// Drawn per episode from its seed (draw_perturbation); nominal: today's world, byte for byte.
  Perturbation perturbation;
  /// What the policy is shown under sensing factors: the observation (none) or an estimate.
  EstimatorConfig estimator;
  std::size_t max_steps = 0;  ///< 0: the world's time limit
  /// What the policy answers (a perturbation's action delay, noise and bias are of that kind).
  /// Joint torques run only on the arm, without an initial push, and not behind the particle filter.
  ActionKind actions = ActionKind::cup;
  std::vector<Episode>* rollouts = nullptr;  ///< if set, receives every rollout in index order
  std::vector<EpisodeResult>* results = nullptr;  ///< if set, receives every rollout's results in index order
  RolloutProgress progress;
};

/// The estimator an evaluation of `model` runs behind, by name: `asked` when not empty, else the
/// one the model was trained to run behind (its record's "estimator", written by a learner whose
/// perturb= has sensing factors or delays), else none. Throws ConfigError for a name that is not
/// an estimator's, naming where it came from.
std::string estimator_for(const std::string& asked, const Model& model);

/// Throws ConfigError, before any work, for an evaluation that could not run: a perturbation
/// the world cannot take, a policy in joint torques where they cannot run, more rollouts than this machine's memory holds, a thread count out of
/// range. evaluate() calls it, and so does every command that evaluates after other work (the
/// leaderboard, the robustness table), so that it refuses before that work.
void check_evaluation(const WorldConfig& world, const EvalRequest& request);

/// Rolls a policy out from request.episodes random starts (evaluation_start_seed(seed, i), in
/// the episode's perturbed world), in parallel on `threads` threads with one world each; the
/// result does not depend on the thread count.
/// Collective over `cluster`: the rollouts are dealt round-robin among its ranks and gathered
/// in index order, so every rank gets the same result for any number of ranks (timings aside:
/// policy_us_per_step sums every rank's policy time, seconds is this rank's wall time).
/// `progress` counts this rank's rollouts, scaled to the whole. Throws ConfigError for a
/// perturbation the world cannot take (validate), before any rollout.
EvalStats evaluate(const PolicyFactory& make_policy, const WorldConfig& world, const EvalRequest& request,
                   Cluster& cluster = local_cluster());

/// Replays every demonstration's actions from its own first state (paper VI-A). Collective over
/// `cluster`, like evaluate.
EvalStats evaluate_playback(const std::vector<Episode>& demos, const WorldConfig& world, int threads,
                            Cluster& cluster = local_cluster());

/// How a policy follows demonstrations when started from each one's first state.
struct Tracking {
  double deviation = 0.0;  ///< mean over demonstrations of the mean over steps of sqrt(eq. 11's term)
  EvalStats stats;         ///< outcomes of those rollouts
};

/// Rolls `policy` out from every demonstration's first state (in parallel, one world per
/// thread; the time limit stretched to cover the longest) and compares with the demonstration.
/// Collective over `cluster`, like evaluate.
Tracking track_demos(const PolicyFactory& make_policy, const std::vector<Episode>& demos, const WorldConfig& world,
                     int threads, Cluster& cluster = local_cluster());

}  // namespace dicestack
