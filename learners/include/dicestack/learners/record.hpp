#pragma once
// Demonstrations from an automatic expert, and the built-in demonstration set made from them.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/policy.hpp>

namespace dicestack {

/// What record_expert runs.
struct RecordRequest {
  int episodes = 0;
  std::uint64_t seed = 0;  ///< episode i starts from random_start_state(world, training_start_seed(seed, first + i))
  /// Where in the seeded sequence the request starts: a long recording asks for it in batches.
  std::uint64_t first = 0;
  int threads = 0;         ///< 0: every core; the result does not depend on it
  /// DART's noise: per action dimension, a fraction of action_scale (the cup's action.scale, or
  /// the arm's torque limits for an expert answering joint torques, whose noise is then given as
  /// Action::torques); the executed actions are perturbed and the expert's clean actions recorded.
  Action noise{0.0, 0.0, 0.0};
  /// Domain randomisation: each episode runs in its own draw (draw_perturbation from its seed);
  /// nominal: today's recordings, byte for byte.
  Perturbation perturbation;
  /// What the expert's feedback acts on: the world (its privilege), or what a policy is shown
  /// (under the perturbation's sensing factors: the observations, or `estimator`'s estimate).
  ExpertFeedback feedback = ExpertFeedback::world;
  /// Between the sensors and the expert's feedback (only with ExpertFeedback::observations).
  EstimatorConfig estimator;
  /// Called with (episodes finished, request.episodes) from one worker as episodes finish (may be
  /// empty); the counts are estimates across ranks.
  std::function<void(int, int)> progress;
};

/// Runs expert `name` from request.episodes random starts, in parallel with one world and one
/// expert per thread. Returns every episode, successes and failures, each with its outcome (and,
/// when perturbed, the values drawn). Throws ConfigError for an unknown expert, a negative noise,
/// a perturbation the world cannot take, or what check_record_request refuses, before any episode. Collective over `cluster`:
/// episodes dealt round-robin among its ranks, every rank gets all of them in index order, the
/// same for any number of ranks.
std::vector<Episode> record_expert(const std::string& name, const ExpertConfig& expert, const WorldConfig& world,
                                   const RecordRequest& request, Cluster& cluster = local_cluster());

/// Throws ConfigError for an expert in joint torques without an arm, and for an estimator nothing reads
/// (the expert's feedback on the world) or that cannot run (an expert answering joint torques:
/// its feedback is turned into torques through the world's own links, not an estimate's). What
/// record_expert checks first, for callers that check before other work.
void check_record_request(ActionKind controller, const WorldConfig& world, const RecordRequest& request);

/// Seed and size of the built-in set.
inline constexpr std::uint64_t kBuiltinSeed = 2026;
inline constexpr int kBuiltinSuccesses = 80;

/// The built-in demonstration set: the first kBuiltinSuccesses realistic successes of the
/// "mpc" expert from random starts seeded with kBuiltinSeed (the paper's "almost 70"), with
/// provenance in meta.json. Generated into the cache on first use (a few seconds), keyed by
/// the world config (folder expert-v3-<world hash>; v3 since the sets carry format v2's
/// transitions, so older caches are not reused); afterwards read from there.
std::filesystem::path builtin_demo_set(const WorldConfig& world, int threads = 0);

/// The folder a demonstration name stands for: "builtin" (the built-in set, generated into the
/// cache on first use), "human" (the paper's 68 recordings, converted), an empty path (the
/// built-in set), or the folder itself. An existing folder called "builtin" or "human" wins.
std::filesystem::path resolve_demo_set(const std::filesystem::path& spec, const WorldConfig& world);

}  // namespace dicestack
