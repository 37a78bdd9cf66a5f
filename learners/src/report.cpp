#include <dicestack/learners/report.hpp>

#include <nlohmann/json.hpp>


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
  if (errors) {
    j["train_error"] = errors->train_error;
    if (errors->test_error) j["test_error"] = *errors->test_error;
    j["split"] = errors->split;
  }
  return j.dump();
}

}  // namespace dicestack
