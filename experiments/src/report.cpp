#include <dicestack/experiments/report.hpp>

#include <nlohmann/json.hpp>

#include <dicestack/version.hpp>

#include "leaderboard_rows.hpp"

namespace dicestack {
namespace {

nlohmann::json rate_json(const Rate& r) { return {r.value, r.low, r.high}; }

}  // namespace

std::string evaluation_json(const EvaluationRun& run, const Model& model, const EvalStats& s, const Score* errors) {
  nlohmann::json j{{"model", run.model},
                   {"regressor", model.regressor().name()},
                   {"features", model.features().name()},
                   {"episodes", s.episodes},
                   {"seed", run.seed},
                   {"initial_push", run.initial_push},
                   {"dice_in_cup_mean", s.dice_in_cup_mean},
                   {"dice_in_cup_3_rate", s.dice_in_cup_3.value},
                   {"stacked_rate", s.stacked.value},
                   {"wall_contact_rate", s.wall_contact.value},
                   {"realistic_success_rate", s.realistic_success.value},
                   {"stacked_rate_ci95", rate_json(s.stacked)},
                   {"wall_contact_rate_ci95", rate_json(s.wall_contact)},
                   {"realistic_success_rate_ci95", rate_json(s.realistic_success)},
                   {"mean_episode_length", s.mean_length},
                   {"us_per_step", s.policy_us_per_step},
                   {"seconds", s.seconds}};
  if (run.perturb != "none") j["perturb"] = run.perturb;
  if (run.estimator != "none") j["estimator"] = run.estimator;
  if (run.start != "random") j["start"] = run.start;
  if (errors) {
    j["train_error"] = errors->train_error;
    if (errors->test_error) j["test_error"] = *errors->test_error;
    j["split"] = errors->split;
  }
  return j.dump();
}

Leaderboard evaluation_board(const EvaluationRun& run, const Model& model, const EvalStats& stats,
                             const std::vector<EpisodeResult>& results, const std::vector<Episode>& rollouts,
                             const WorldConfig& world, const Score* errors) {
  const auto learner = model.record.find("learner");
  LeaderboardRow row{model.regressor().name(), learner == model.record.end() ? "-" : learner->second, model.features().name()};
  row.train_error = errors ? errors->train_error : -1;
  row.test_error = errors && errors->test_error ? *errors->test_error : -1;
  row.fit_s = -1;
  add_outcomes(row, stats, 1);
  std::vector<RowPreview> success, failure;
  pick_previews(rollouts, run.seed, success, failure);
  add_rollouts(row, run.seed, results, success, failure);
  Leaderboard board;
  board.rows.push_back(std::move(row));
  board.world = world;
  board.header = "dicestack " DICESTACK_VERSION " evaluation of " + run.model + ": " + std::to_string(stats.episodes) +
                 " rollouts from " + run.start + " starts (seed " + std::to_string(run.seed) + "); rates with 95% Wilson intervals";
  nlohmann::json meta{{"model", run.model},        {"dicestack_version", DICESTACK_VERSION},
                      {"regressor", model.regressor().name()}, {"features", model.features().name()},
                      {"episodes", stats.episodes}, {"seed", run.seed},
                      {"initial_push", run.initial_push}};
  if (run.perturb != "none") meta["perturb"] = run.perturb;
  if (run.estimator != "none") meta["estimator"] = run.estimator;
  if (run.start != "random") meta["start"] = run.start;
  for (const auto& [key, value] : model.record) meta["training " + key] = value;
  board.meta_json = meta.dump();
  return board;
}

}  // namespace dicestack
