#pragma once
// What `dicestack evaluate --json` and `--report` report, built in one place for the command
// line and the Python package (whose evaluate() returns the same keys).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/score.hpp>

namespace dicestack {

/// How the rollouts were asked for.
struct EvaluationRun {
  std::string model;                ///< the model file as the user named it
  std::uint64_t seed = 0;
  std::string initial_push = "none";
  std::string perturb = "none";  ///< --perturb as given: a level or a file (in the JSON unless none)
  std::string start = "random";  ///< the start distribution (initial_state.hpp's with_starts)
  std::string estimator = "none";  ///< between the sensors and the policy (in the JSON unless none)
};

/// The `evaluate --json` object as one line of JSON: model, regressor, features, episodes,
/// seed, initial_push, dice_in_cup_mean, dice_in_cup_3_rate, stacked_rate, wall_contact_rate,
/// realistic_success_rate (each rate also as [value, low, high] under *_ci95),
/// mean_episode_length, us_per_step, seconds, start, perturb and estimator unless random and none, and train_error, test_error, split when `errors`
/// is given.
std::string evaluation_json(const EvaluationRun& run, const Model& model, const EvalStats& stats,
                            const Score* errors = nullptr);

/// One model's evaluation as a one-row leaderboard, for its results page (results_page.hpp):
/// the row (learner from the model's training record), its rollouts' `results` and the first
/// successful and first failed of `rollouts` as previews; the header facts are the run's.
Leaderboard evaluation_board(const EvaluationRun& run, const Model& model, const EvalStats& stats,
                             const std::vector<EpisodeResult>& results, const std::vector<Episode>& rollouts,
                             const WorldConfig& world, const Score* errors = nullptr);

}  // namespace dicestack
