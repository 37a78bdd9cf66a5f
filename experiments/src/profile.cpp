#include <dicestack/experiments/profile.hpp>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

std::vector<Profile> make_profiles() {
  Profile quick;
  quick.name = "quick";
  quick.rollouts = 20;
  // The tracker's gbt row with dart's own defaults (1200 episodes: 66 s of the main job) but
  // without refining the path: that costs about 100 s, more than the main job's minutes allow,
  // and its row stacks in 20 of 20 without.
  quick.learner_options = {{"dagger", {"iterations=2", "rollouts=10"}},
                           {"dad", {"windows=2", "iterations=1", "corrector_iterations=10"}},
                           {"dart:expert=tracker", {"tracker_demos=human", "tracker_refine=0"}}};
  // A kernel SVR fitted on DART's ~60,000 rows alone would take longer than the rest (its rows are O(n^2)).
  // Learning from the recordings alone: DART labelled by the tracker, which follows the paper's
  // human recordings' cup paths (no hand-made expert). One regressor keeps the main job within its minutes.
  quick.learners = {"bc", "dagger", "dart", "dart:expert=tracker"};
  quick.left_out = {{"dart", "rbf_svr"}};
  for (const char* r : {"knn", "linear_svr", "mlp", "random_forest"}) quick.left_out.emplace_back("dart:expert=tracker", r);
  quick.left_out_note =
      "left out of the quick profile: rbf_svr under dart (200 s to fit 60,000 rows) and dart:expert=tracker but for "
      "gbt (the main job's minutes); name the regressors with --regressors or use --profile paper";

  Profile paper;
  paper.name = "paper";
  paper.rollouts = 100;
  // Every regressor learns the tracker's row: at DART's 300 episodes, not its 1200 (a kernel
  // SVR's fit grows with the square of the rows), and so with no narrowing, which pays only with
  // more episodes (built-in set, gbt: 36 / 37 % narrowed, 55 / 47 % not;
  // docs/notebook/2026-11-27-learners-page-history.md, "The paper profile"), and unrefined:
  // refining costs about 100 s per row, and the paper profile trains one row per regressor and map.
  paper.learner_options = {{"dagger", {"iterations=5", "rollouts=20"}},  // dad: its defaults
                           {"dart:expert=tracker", {"episodes=300", "tracker_shrink=0", "tracker_refine=0"}}};
  paper.learners = {"bc", "dagger", "dart", "dart:expert=tracker"};
  paper.every_feature_map = true;
  paper.optimiser_evaluations = 5000;
  paper.bayes_evaluations = 500;
  paper.reinforce_iterations = 1000;
  paper.rrt_nodes = 1000;
  return {quick, paper};
}

const std::vector<Profile>& profiles() {
  static const std::vector<Profile> all = make_profiles();
  return all;
}

}  // namespace

std::vector<std::string> Profile::options_for(const std::string& learner, const std::string& spec) const {
  std::vector<std::string> out;
  for (const std::string* key : {&learner, &spec})
    if (const auto it = learner_options.find(*key); it != learner_options.end() && (key == &learner || spec != learner))
      out.insert(out.end(), it->second.begin(), it->second.end());
  return out;
}

const Profile& leaderboard_profile(const std::string& name) {
  for (const auto& p : profiles())
    if (p.name == name) return p;
  std::string list;
  for (const auto& p : profiles()) list += (list.empty() ? "" : ", ") + p.name;
  throw ConfigError("leaderboard: profile \"" + name + "\" is not one of " + list);
}

std::vector<std::string> leaderboard_profile_names() {
  std::vector<std::string> out;
  for (const auto& p : profiles()) out.push_back(p.name);
  return out;
}

}  // namespace dicestack
