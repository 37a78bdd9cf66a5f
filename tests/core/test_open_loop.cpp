#include <gtest/gtest.h>

#include <vector>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/open_loop.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

OpenLoopSettings short_sequence() {
  OpenLoopSettings s;
  s.steps = 6;
  return s;
}

TEST(OpenLoop, CostIsEquationSixAlongTheScaledSequence) {
  WorldConfig w;
  OpenLoopProblem p(w, short_sequence(), 1);
  std::vector<double> x(p.dim());
  Rng rng(3);
  for (double& v : x) v = rng.uniform(-1.0, 1.0);
  // By hand: the actions are x times the scale, the states are those after each step.
  DiceEnv env(w);
  env.reset_to(paper_start_state(w), derive_seed(0, 0));
  std::vector<State> states;
  for (std::size_t t = 0; t < 6; ++t)
    states.push_back(env.step({x[3 * t] * 1.0, x[3 * t + 1] * 0.1, x[3 * t + 2] * 0.5}).observation);
  EXPECT_EQ(p.cost(x.data()), discounted_cost(states, goal_state(w), w.cost));
  EXPECT_EQ(p.evaluations(), 1);
}

TEST(OpenLoop, BatchesEqualOneByOneWhateverTheThreads) {
  WorldConfig w;
  OpenLoopProblem one(w, short_sequence(), 1), two(w, short_sequence(), 2);
  Eigen::MatrixXd xs(9, static_cast<Eigen::Index>(one.dim()));
  Rng rng(5);
  for (Eigen::Index i = 0; i < xs.size(); ++i) xs.data()[i] = rng.uniform(-1.5, 1.5);  // clipped to the box
  const auto a = one.cost_batch(xs), b = two.cost_batch(xs);
  EXPECT_EQ(a, b);
  for (Eigen::Index r = 0; r < xs.rows(); ++r) {
    const Eigen::VectorXd row = xs.row(r).transpose();
    EXPECT_EQ(one.cost(row.data()), a[static_cast<std::size_t>(r)]);
  }
}

class OptimiserTest : public ::testing::TestWithParam<std::string> {};

TEST_P(OptimiserTest, ImprovesDeterministicallyAndReportsItsBestHonestly) {
  WorldConfig w;
  OptimiseOptions o;
  o.method = GetParam();
  o.evaluations = 120;
  o.seed = 9;
  OpenLoopProblem p1(w, short_sequence(), 2), p2(w, short_sequence(), 1);
  const OptimiseResult a = optimise(p1, o), b = optimise(p2, o);
  EXPECT_EQ(a.best, b.best) << "same seed, other thread count";
  EXPECT_EQ(a.best_cost, b.best_cost);
  EXPECT_LE(a.evaluations, o.evaluations);
  EXPECT_GT(a.evaluations, o.evaluations / 2);
  // The reported best is what the sequence costs, and no worse than the first generation.
  OpenLoopProblem check(w, short_sequence(), 1);
  EXPECT_EQ(check.cost(a.best.data()), a.best_cost);
  ASSERT_FALSE(a.curve.empty());
  EXPECT_LE(a.best_cost, a.curve.front().second);
  for (std::size_t k = 1; k < a.curve.size(); ++k) EXPECT_LE(a.curve[k].second, a.curve[k - 1].second);
  for (double v : a.best) EXPECT_LE(std::abs(v), 1.0);
}

INSTANTIATE_TEST_SUITE_P(OpenLoop, OptimiserTest, ::testing::Values("cmaes", "de", "basinhop", "bayes"));

TEST(OpenLoop, BadSettingsAreRejected) {
  WorldConfig w;
  OpenLoopProblem p(w, short_sequence(), 1);
  OptimiseOptions o;
  o.method = "annealing";
  EXPECT_THROW(optimise(p, o), ConfigError);
  OpenLoopSettings s;
  s.steps = 0;
  EXPECT_THROW(OpenLoopProblem(w, s, 1), ConfigError);
}

}  // namespace
}  // namespace dicestack
