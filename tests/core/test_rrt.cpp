#include <gtest/gtest.h>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rrt.hpp>

namespace dicestack {
namespace {

TEST(Rrt, ThePathReplaysToTheReportedNodeWhateverTheThreads) {
  RrtOptions o;
  o.nodes = 12;
  o.extend_steps = 3;
  o.extend_iterations = 2;
  o.goal_bias = 0.5;
  o.seed = 8;
  o.threads = 1;
  const RrtResult a = rrt(WorldConfig{}, o);
  o.threads = 2;
  const RrtResult b = rrt(WorldConfig{}, o);
  EXPECT_EQ(a.actions, b.actions);
  EXPECT_EQ(a.best_distance, b.best_distance);
  EXPECT_EQ(a.nodes, 12);
  EXPECT_EQ(a.actions.size() % 3, 0u);
  // Replaying the path from the start reaches the node: snapshots are exact.
  WorldConfig w;
  DiceEnv env(w);
  env.reset_to(paper_start_state(w), 0);
  for (const Action& x : a.actions) env.step(x);
  EXPECT_EQ(state_distance(env.get_state(), goal_state(w), w.cost), a.best_distance);
  EXPECT_LE(a.best_distance, state_distance(paper_start_state(w), goal_state(w), w.cost));
  o.extend_steps = 0;
  EXPECT_THROW(rrt(WorldConfig{}, o), ConfigError);
}

}  // namespace
}  // namespace dicestack
