// The baseline registry: every optimiser, then REINFORCE and RRT, each with a cost estimate that
// grows with its budget, and a policy that depends on its seed, not on the threads.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/experiments/baseline.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/experiments/profile.hpp>

#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

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

}  // namespace
}  // namespace dicestack
