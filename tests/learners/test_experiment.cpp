// The experiment layer under the leaderboard and the commands: score, profiles, the baseline
// registry and outcome counts.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/metrics.hpp>
#include <dicestack/learners/baseline.hpp>
#include <dicestack/test/requests.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/leaderboard.hpp>
#include <dicestack/learners/profile.hpp>
#include <dicestack/regressors/registry.hpp>
#include <dicestack/regressors/score.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

std::vector<Episode> good_episodes() {
  return read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good").episodes;
}

TEST(Score, IsEquationNineWithSigmaFromTheTrainingLabelsAndNoTestErrorWithoutTestRows) {
  std::vector<Episode> eps = good_episodes();
  while (eps.size() < 5) {  // a fifth episode makes a test side
    const Episode copy = eps[eps.size() % 2];
    eps.push_back(copy);
  }
  const DemoSplit split(eps, "episodes");
  const Split& m = split.matrices();
  const Model model = Model::train(RegressorRegistry::global().create("linear_svr"), m.train.x, m.train.y, 1);
  const Score s = score(model, split);
  const auto sigma = column_sigma(m.train.y);
  EXPECT_EQ(s.train_error, scaled_l1_error(m.train.y, model.predict(m.train.x), sigma));
  ASSERT_TRUE(s.test_error.has_value());
  EXPECT_EQ(*s.test_error, scaled_l1_error(m.test.y, model.predict(m.test.x), sigma));
  EXPECT_EQ(s.split, m.description);

  const Score all = score(model, DemoSplit(eps, "none"));  // no test rows: none, not 0
  EXPECT_FALSE(all.test_error.has_value());
  EXPECT_THAT(all.split, HasSubstr("none"));
}

TEST(Profile, QuickAndPaperAreDataAndOtherNamesAreRefused) {
  EXPECT_EQ(leaderboard_profile_names(), (std::vector<std::string>{"quick", "paper"}));
  const Profile& quick = leaderboard_profile("quick");
  const Profile& paper = leaderboard_profile("paper");
  EXPECT_EQ(quick.rollouts, 20);
  EXPECT_EQ(paper.rollouts, 100);
  EXPECT_FALSE(quick.every_feature_map);
  EXPECT_TRUE(paper.every_feature_map);
  // Both profiles learn from the recordings alone (the tracker); the quick one with gbt only.
  const std::vector<std::string> learners{"bc", "dagger", "dart", "dart:expert=tracker"};
  EXPECT_EQ(quick.learners, learners);
  EXPECT_EQ(paper.learners, learners);
  EXPECT_EQ(quick.left_out.front(), (std::pair<std::string, std::string>{"dart", "rbf_svr"}));
  for (const char* r : {"knn", "linear_svr", "mlp", "random_forest"})
    EXPECT_NE(std::find(quick.left_out.begin(), quick.left_out.end(), std::pair<std::string, std::string>{"dart:expert=tracker", r}),
              quick.left_out.end());
  EXPECT_TRUE(paper.left_out.empty());
  EXPECT_EQ(quick.learner_options.at("dagger"), (std::vector<std::string>{"iterations=2", "rollouts=10"}));
  // A row spec's own defaults: the quick profile's tracker row follows the human recordings
  // whatever --demos names; the paper profile's tracker rows keep a kernel SVR's fit in bounds.
  EXPECT_EQ(quick.learner_options.at("dart:expert=tracker"), (std::vector<std::string>{"tracker_demos=human"}));
  EXPECT_EQ(paper.learner_options.at("dart:expert=tracker"), (std::vector<std::string>{"episodes=300", "tracker_shrink=0"}));
  EXPECT_EQ(paper.options_for("dart", "dart:expert=tracker"), (std::vector<std::string>{"episodes=300", "tracker_shrink=0"}));
  EXPECT_EQ(quick.options_for("dart", "dart:expert=tracker"), (std::vector<std::string>{"tracker_demos=human"}));
  EXPECT_TRUE(quick.options_for("dart", "dart").empty());
  EXPECT_EQ(quick.options_for("dagger", "dagger"), (std::vector<std::string>{"iterations=2", "rollouts=10"}))
      << "a spec that is the learner's name is looked up once";
  EXPECT_GT(paper.optimiser_evaluations, quick.optimiser_evaluations);
  try {
    leaderboard_profile("huge");
    FAIL() << "no exception";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("profile \"huge\" is not one of quick, paper"));
  }
}

TEST(Baselines, RegistryListsEveryOptimiserThenReinforceAndRrt) {
  EXPECT_EQ(baseline_names(), (std::vector<std::string>{"cmaes", "de", "basinhop", "bayes", "reinforce", "rrt"}));
  try {
    baseline("annealing");
    FAIL() << "no exception";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown baseline \"annealing\"; expected cmaes, de, basinhop, bayes, reinforce, rrt or all"));
  }
  // A baseline's estimated cost grows with its own budget: 5x the evaluations for the
  // optimisers, 2.5x for bayes, 10x the updates and nodes for reinforce and rrt (rollouts: 0).
  const Profile &quick = leaderboard_profile("quick"), &paper = leaderboard_profile("paper");
  for (const auto& [name, ratio] : std::vector<std::pair<std::string, double>>{
           {"cmaes", 5.0}, {"de", 5.0}, {"basinhop", 5.0}, {"bayes", 2.5}, {"reinforce", 10.0}, {"rrt", 10.0}})
    EXPECT_DOUBLE_EQ(estimated_row_cost("baseline", name, "-", paper, 0) / estimated_row_cost("baseline", name, "-", quick, 0),
                     ratio)
        << name;
}

TEST(Baselines, APolicyMadeWithATinyBudgetDependsOnItsSeedNotOnTheThreads) {
  WorldConfig world;
  world.episode.max_steps = 30;
  Profile tiny = leaderboard_profile("quick");
  tiny.optimiser_evaluations = 60;  // three CMA-ES generations of 19
  tiny.rrt_nodes = 4;
  tiny.reinforce_iterations = 1;
  auto actions_of = [&](const std::string& name, std::uint64_t seed, int threads) {
    std::vector<Episode> rollouts;
    const EvalStats s = evaluate(baseline(name).make(world, tiny, seed, threads), world, test::eval_request(1, 0, 1, &rollouts));
    EXPECT_EQ(s.episodes, 1) << name;
    return rollouts.at(0).actions;
  };
  for (const std::string name : {"cmaes", "reinforce"}) {
    const auto a = actions_of(name, 3, 1);
    ASSERT_FALSE(a.empty()) << name;
    EXPECT_EQ(actions_of(name, 3, 2), a) << name;
    EXPECT_NE(actions_of(name, 4, 1), a) << name;
  }
  // An RRT this small finds no node nearer the goal than the resting start: it plays nothing
  // (its determinism over threads is RrtTest's and Mpi.rrt's).
  EXPECT_EQ(actions_of("rrt", 3, 1), std::vector<Action>(30, Action{0.0, 0.0, 0.0}));
}

TEST(OutcomeCounts, AreTheRatesTimesTheEpisodes) {
  EvalStats s;
  s.episodes = 7;
  s.stacked = wilson(3, 7);
  s.wall_contact = wilson(7, 7);
  s.realistic_success = wilson(0, 7);
  const OutcomeCounts n = outcome_counts(s);
  EXPECT_EQ(n.episodes, 7);
  EXPECT_EQ(n.stacked, 3);
  EXPECT_EQ(n.wall_contact, 7);
  EXPECT_EQ(n.realistic_success, 0);
}

}  // namespace
}  // namespace dicestack
