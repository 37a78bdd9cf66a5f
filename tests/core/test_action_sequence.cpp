#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <dicestack/core/action_sequence.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>

namespace dicestack {
namespace {

// A known bowl: the squared distance of the actions (in scaled units) from a target inside the
// box. The environment is ignored except that the cost runs one step in it, as real costs do.
ActionSequenceProblem bowl(const WorldConfig& w, ActionBox box, const std::vector<double>& target) {
  return ActionSequenceProblem(w, static_cast<int>(target.size() / kActionDim), box,
                               [&w, target](DiceEnv& env, const std::vector<Action>& actions) {
                                 env.reset_to(paper_start_state(w), 0);
                                 env.step(actions[0]);
                                 double c = 0.0;
                                 for (std::size_t i = 0; i < target.size(); ++i) {
                                   const double x = actions[i / kActionDim][i % kActionDim] / w.action.scale[i % kActionDim];
                                   c += (x - target[i]) * (x - target[i]);
                                 }
                                 return c;
                               });
}

const std::vector<double> kTarget{0.3, -0.5, 0.1, -0.2, 0.6, 0.0};

class Minimiser : public ::testing::TestWithParam<std::string> {};

TEST_P(Minimiser, FindsTheBowlsBottomTheSameWayOnAnyThreadCount) {
  const WorldConfig w;
  const ActionSequenceProblem p = bowl(w, ActionBox::unit, kTarget);
  MinimiseOptions o;
  o.method = GetParam();
  o.evaluations = 300;
  o.seed = 5;
  EnvPool one_pool(w, 1), two_pool(w, 2);
  SequenceEvaluator one(one_pool, 1), two(two_pool, 2);
  const MinimiseResult a = minimise(p, one, o), b = minimise(p, two, o);
  double start = 0.0;  // the cost at x = 0, where every method starts
  for (double t : kTarget) start += t * t;
  EXPECT_LT(a.best_cost, 0.25 * start) << GetParam();
  EXPECT_EQ(a.best, b.best);
  EXPECT_EQ(a.best_cost, b.best_cost);
  EXPECT_EQ(a.curve, b.curve);
  EXPECT_EQ(a.evaluations, one.evaluations());
  EXPECT_LE(a.evaluations, 300 + 13) << "a CMA-ES generation may end past the budget, nothing more";
  // The reported best is a point of the box whose cost is the reported one.
  DiceEnv env(w);
  EXPECT_EQ(p.cost(env, a.best.data()), a.best_cost);
  ASSERT_FALSE(a.curve.empty());
  for (std::size_t i = 1; i < a.curve.size(); ++i) EXPECT_LE(a.curve[i].second, a.curve[i - 1].second);
}

TEST_P(Minimiser, SearchesTheLimitsBoxFromX0) {
  // The bottom lies outside the unit box but inside action.limit / action.scale (20, 200, 20);
  // a search started near it keeps within the box and does no worse than its start.
  const WorldConfig w;
  const ActionSequenceProblem p = bowl(w, ActionBox::limits, {3.0, -4.0, 2.0});
  EXPECT_EQ(p.bound(0), 20.0);
  EXPECT_EQ(p.bound(1), 200.0);
  EXPECT_EQ(p.bound(2), 20.0);
  MinimiseOptions o;
  o.method = GetParam();
  o.iterations = 3;
  o.x0 = Eigen::Vector3d(3.5, -3.5, 2.5);
  DiceEnv env(w);
  const double at_x0 = p.cost(env, o.x0->data());
  SequenceEvaluator e(env);
  const MinimiseResult r = minimise(p, e, o);
  EXPECT_LE(r.best_cost, at_x0) << GetParam();
  for (Eigen::Index i = 0; i < 3; ++i) EXPECT_LE(std::abs(r.best[i]), p.bound(static_cast<std::size_t>(i)));
}

INSTANTIATE_TEST_SUITE_P(ActionSequence, Minimiser, ::testing::ValuesIn(minimiser_names()));

TEST(ActionSequence, ActionsAreTheClippedPointTimesTheScale) {
  const WorldConfig w;
  const ActionSequenceProblem p(w, 2, ActionBox::unit, [](DiceEnv&, const std::vector<Action>&) { return 0.0; });
  const double x[6] = {0.5, 2.0, -3.0, -0.25, 0.1, 1.0};
  const std::vector<Action> a = p.actions(x);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0], (Action{0.5, 0.1, -0.5}));
  EXPECT_EQ(a[1], (Action{-0.25, 0.1 * 0.1, 0.5}));
  const Eigen::VectorXd back = p.point(a);
  EXPECT_EQ(back[1], 1.0);
  EXPECT_EQ(back[2], -1.0);
}

TEST(ActionSequence, BadRequestsAreRefused) {
  const WorldConfig w;
  EXPECT_THROW(ActionSequenceProblem(w, 0, ActionBox::unit, {}), ConfigError);
  const ActionSequenceProblem p = bowl(w, ActionBox::unit, kTarget);
  DiceEnv env(w);
  SequenceEvaluator e(env);
  MinimiseOptions o;
  EXPECT_THROW(minimise(p, e, o), ConfigError) << "no budget";
  o.evaluations = 10;
  o.method = "annealing";
  EXPECT_THROW(minimise(p, e, o), ConfigError);
  o.method = "cmaes";
  o.x0 = Eigen::VectorXd::Zero(2);
  EXPECT_THROW(minimise(p, e, o), ConfigError) << "x0 of another size";
  EXPECT_EQ(e.evaluations(), 0);
}

}  // namespace
}  // namespace dicestack
