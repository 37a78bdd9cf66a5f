#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/initial_state.hpp>

namespace dicestack {
namespace {

TEST(Cost, DistanceScalesByTheStateSigmaAndIgnoresTheCupPose) {
  const WorldConfig c;
  const State goal = goal_state(c);
  EXPECT_EQ(state_distance(goal, goal, c.cost), 0.0);
  State s = goal;
  s[state_index::kCupX] += 3.0;  // cup pose is free
  s[state_index::kCupAngle] += 1.0;
  EXPECT_EQ(state_distance(s, goal, c.cost), 0.0);
  s[state_index::die(0)] += 2.0 * c.cost.sigma[state_index::die(0)];
  s[state_index::kCupVx] += 1.0 * c.cost.sigma[state_index::kCupVx];
  EXPECT_NEAR(state_distance(s, goal, c.cost), std::sqrt(4.0 + 1.0), 1e-12);
}

TEST(Cost, DieAnglesCompareModuloQuarterTurns) {
  const WorldConfig c;
  const State goal = goal_state(c);
  State s = goal;
  s[state_index::die(1) + 2] = 3.0 * std::numbers::pi / 2.0;
  EXPECT_NEAR(state_distance(s, goal, c.cost), 0.0, 1e-12);
}

TEST(Cost, DiscountWeighsLaterStatesMore) {
  WorldConfig c;
  c.cost.gamma = 0.5;
  const State goal = goal_state(c);
  std::vector<State> traj(3, goal);
  traj[0][state_index::die(0)] += c.cost.sigma[state_index::die(0)];        // d = 1, weight 0.25
  traj[2][state_index::die(0)] += 2.0 * c.cost.sigma[state_index::die(0)];  // d = 2, weight 1
  EXPECT_NEAR(discounted_cost(traj, goal, c.cost), 0.25 * 1.0 + 2.0, 1e-12);
  c.cost.gamma = 0.0;
  EXPECT_NEAR(discounted_cost(traj, goal, c.cost), 2.0, 1e-12);
}

}  // namespace
}  // namespace dicestack
