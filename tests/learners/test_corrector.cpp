// DaD's correctors: each one's corrections follow the demonstration better, its labels are in
// the demonstration's units, and the paper's search from a random start keeps its own best.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/corrector.hpp>

#include <dicestack/test/demos.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using test::demos;

// The window [t, t + w) of demonstration 0, starting from its exact world.
CorrectionProblem window_of(DiceEnv& env, const Episode& demo, std::size_t t, std::size_t w) {
  env.reset_to(demo.states[0], demo.seed);
  for (std::size_t k = 0; k < t; ++k) env.step(demo.actions[k]);
  CorrectionProblem p{env.snapshot(), {}, {}, CorrectionTarget::state, {}, {}};
  for (std::size_t k = t; k < t + w; ++k) {
    p.target.push_back(demo.states[k + 1]);
    p.warm.push_back(demo.actions[k]);
    p.reference.push_back(demo.states[k]);
    p.reference_actions.push_back(demo.actions[k]);
  }
  return p;
}

class Correctors : public ::testing::TestWithParam<std::string> {};

TEST_P(Correctors, CorrectionsReduceTheDeviationFromTheDemonstration) {
  DiceEnv env(test::short_world());
  const Episode& demo = demos()[0];
  CorrectionProblem p = window_of(env, demo, 10, 8);
  for (auto& a : p.warm) a[0] += 0.6, a[1] -= 0.05;  // a policy that drifts
  const Correction fix = make_corrector(GetParam(), {20, 0.25, 0, 10.0})->correct(env, p, 3);
  EXPECT_GT(fix.warm_cost, 0.0);
  EXPECT_LT(fix.cost, 0.5 * fix.warm_cost) << GetParam();
  // The labels are what the world applies: replaying them gives the recorded trajectory.
  std::vector<State> replay;
  EXPECT_EQ(window_cost(env, p, fix.actions, &replay), fix.cost);
  EXPECT_EQ(replay, fix.states);
  ASSERT_EQ(fix.states.size(), 8u);
  EXPECT_TRUE(test::bit_equal(fix.states[0], demo.states[10]));
  for (const auto& a : fix.actions)
    for (std::size_t k = 0; k < kActionDim; ++k) EXPECT_LE(std::abs(a[k]), env.config().action.limit[k]);
}

TEST_P(Correctors, LabelsAreInTheDemonstrationsUnits) {
  // From the demonstration's own world with its own actions there is nothing to correct: the
  // corrector must hand back exactly those actions, in the units they were recorded in. A
  // corrector that returned its search variables (action / scale) would fail here: the scales
  // are 1, 0.1 and 0.5.
  DiceEnv env(test::short_world());
  const Episode& demo = demos()[0];
  const CorrectionProblem p = window_of(env, demo, 20, 6);
  const Correction fix = make_corrector(GetParam(), {5, 0.25, 0, 10.0})->correct(env, p, 4);
  EXPECT_EQ(fix.warm_cost, 0.0);
  EXPECT_EQ(fix.cost, 0.0);
  ASSERT_EQ(fix.actions.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(fix.actions[k], demo.actions[20 + k]) << "step " << k;
}

INSTANTIATE_TEST_SUITE_P(Dad, Correctors, ::testing::ValuesIn(corrector_names()));

TEST(Correctors, FromARandomStartItKeepsItsBestEvenWhereThePolicysActionsScoreBetter) {
  // The paper's code: CMA-ES from a random point, its best returned whatever the policy did.
  // From the demonstration's own world the policy's actions cost 0, which a short search from
  // elsewhere does not reach; and the dice and the cup's velocity are what it aims at.
  DiceEnv env(test::short_world());
  const Episode& demo = demos()[0];
  CorrectionProblem p = window_of(env, demo, 20, 1);
  p.aim = CorrectionTarget::dice;
  CorrectorOptions o;
  o.evaluations = 40;
  o.sigma0 = 0.8;
  o.random_start = true;
  const Correction fix = make_corrector("cmaes", o)->correct(env, p, 4);
  EXPECT_EQ(fix.warm_cost, 0.0);
  EXPECT_GT(fix.cost, 0.0);
  EXPECT_LE(fix.evaluations, 40 + 7 + 2);  // the budget, its last generation, the warm start and the replay
  EXPECT_NE(fix.actions[0], demo.actions[20]);
  const Correction again = make_corrector("cmaes", o)->correct(env, p, 4);
  EXPECT_EQ(again.actions, fix.actions);  // seeded
}

}  // namespace
}  // namespace dicestack
