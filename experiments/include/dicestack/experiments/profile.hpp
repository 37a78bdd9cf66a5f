#pragma once
// A leaderboard profile (`--profile`) as data: the budgets of a run, so that a new profile is a
// table entry and the leaderboard does not branch on its name.
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace dicestack {

struct Profile {
  std::string name;
  int rollouts = 20;  ///< evaluation rollouts per row and training seed (unless --episodes)
  /// The learner rows when none are named (specs, as --learners takes them).
  std::vector<std::string> learners{"bc", "dagger", "dart"};
  /// Learner options applied before the user's --option, by learner ("dart") and then by row spec
  /// ("dart:expert=tracker"); learners not listed: their defaults.
  std::map<std::string, std::vector<std::string>> learner_options;
  /// Every learner also with the bare state and with dart's feature map (the paper's picture);
  /// otherwise each learner with its own default map.
  bool every_feature_map = false;
  /// (learner, regressor) rows left out unless the regressors are named, and why (for the header).
  std::vector<std::pair<std::string, std::string>> left_out;
  std::string left_out_note;
  // Budgets of the baselines without demonstrations.
  int optimiser_evaluations = 1000;  ///< cmaes, de, basinhop
  int bayes_evaluations = 200;       ///< Bayesian optimisation (each evaluation refits a GP)
  int reinforce_iterations = 100;
  int rrt_nodes = 100;

  /// The options this profile gives a learner row, in order of application: those for the
  /// learner ("dart"), then those for the row's spec ("dart:expert=tracker").
  std::vector<std::string> options_for(const std::string& learner, const std::string& spec) const;
};

/// "quick" (minutes on 2 cores) or "paper" (the paper's budgets; about an hour and a half).
/// Throws ConfigError naming the profiles for another name.
const Profile& leaderboard_profile(const std::string& name);
std::vector<std::string> leaderboard_profile_names();

}  // namespace dicestack
