#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
using test::bit_equal;

TEST(Env, ResetIsSeededAndObservationsStayInBounds) {
  const WorldConfig c;
  DiceEnv env(c), other(c);
  const State a = env.reset(7);
  EXPECT_TRUE(bit_equal(a, other.reset(7)));
  EXPECT_FALSE(bit_equal(a, other.reset(8)));
  const auto box = env.observation_space();
  for (const auto& act : test::random_actions(c, 1, 200)) {
    const State s = env.step(act).observation;
    for (std::size_t j = 0; j < kStateDim; ++j) {
      EXPECT_GE(s[j], box.low[j]) << j;
      EXPECT_LE(s[j], box.high[j]) << j;
    }
  }
}

TEST(Env, ActionsAreClippedToTheLimits) {
  const WorldConfig c;
  DiceEnv a(c), b(c);
  State start = paper_start_state(c);
  start[si::kCupY] = 5.0;
  a.reset_to(start);
  b.reset_to(start);
  a.step({100.0, 0.0, -50.0});
  b.step({c.action.limit[0], 0.0, -c.action.limit[2]});
  EXPECT_TRUE(bit_equal(a.get_state(), b.get_state()));
  EXPECT_EQ(a.action_space().high[0], c.action.limit[0]);
  EXPECT_THROW(a.step({std::nan(""), 0.0, 0.0}), InputError);
}

TEST(Env, RewardsSumToMinusTheDiscountedCost) {
  WorldConfig c;
  c.episode.max_steps = 20;
  c.cost.gamma = 0.5;
  DiceEnv env(c);
  env.reset(3);
  std::vector<State> states;
  double total = 0.0;
  StepResult r;
  for (const auto& act : test::random_actions(c, 2, 20)) {
    r = env.step(act);
    total += r.reward;
    states.push_back(r.observation);
  }
  EXPECT_TRUE(r.truncated);
  EXPECT_FALSE(r.terminated);
  EXPECT_EQ(r.info.t, 20);
  EXPECT_NEAR(total, -discounted_cost(states, goal_state(c), c.cost), 1e-9);
}

TEST(Env, TerminatesAfterRealisticSuccessHolds) {
  const WorldConfig c;
  State s{};
  s[si::kCupX] = 7.5;
  s[si::kCupY] = 1.0 + 0.05 + 2.2 / 3.0;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    s[si::die(i)] = 3.0;
    s[si::die(i) + 1] = 1.2 + 0.4 * static_cast<double>(i);
  }
  DiceEnv env(c);
  env.reset_to(s);
  StepResult r;
  int steps = 0;
  do {
    r = env.step({0.0, 0.0, 0.0});
    ++steps;
  } while (!r.terminated && steps < 50);
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(steps, c.judge.success_hold_steps);
  EXPECT_TRUE(r.info.outcome.realistic_success());
}

TEST(Env, NoiseIsSeededAndChangesTheRun) {
  WorldConfig noisy;
  noisy.physics.action_noise = 0.3;
  const auto actions = test::random_actions(noisy, 4, 60);
  auto run = [&](const WorldConfig& c, std::uint64_t seed) {
    DiceEnv env(c);
    env.reset(seed);
    for (const auto& a : actions) env.step(a);
    return env.get_state();
  };
  EXPECT_TRUE(bit_equal(run(noisy, 5), run(noisy, 5)));
  EXPECT_FALSE(bit_equal(run(noisy, 5), run(WorldConfig{}, 5)));
}

}  // namespace
}  // namespace dicestack
