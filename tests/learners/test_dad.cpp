#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/corrector.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

// Scripted-expert episodes of 60 steps: demonstrations the world replays bit for bit.
const std::vector<Episode>& demos() {
  static const std::vector<Episode> d = record_expert("scripted", {}, test::short_world(), test::record_request(3, 5, 1));
  return d;
}

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

class CorrectorTest : public ::testing::TestWithParam<std::string> {};

TEST_P(CorrectorTest, CorrectionsReduceTheDeviationFromTheDemonstration) {
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

TEST_P(CorrectorTest, LabelsAreInTheDemonstrationsUnits) {
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

INSTANTIATE_TEST_SUITE_P(Dad, CorrectorTest, ::testing::ValuesIn(corrector_names()));

TEST(Dad, UnknownCorrectorIsRejected) {
  EXPECT_THROW(make_corrector("annealing", {}), ConfigError);
  EXPECT_THROW(LearnerRegistry::global().create("dad", {"corrector=annealing"}), ConfigError);
}

LearnContext dad_context(int threads) {
  LearnContext c;
  c.world = test::short_world();
  c.regressor = "knn";
  c.seed = 21;
  c.threads = threads;
  c.demos = demos();
  return c;
}

const std::vector<std::string> kSmall{"windows=2", "iterations=2", "corrector_iterations=2", "demos=2", "filter=false"};

TEST(Dad, CorrectionsAreAddedOnceAndResultsIgnoreThreads) {
  const LearnResult one = LearnerRegistry::global().create("dad", kSmall)->learn(dad_context(1));
  const LearnResult two = LearnerRegistry::global().create("dad", kSmall)->learn(dad_context(2));
  const Dataset probe = make_dataset(demos());
  EXPECT_EQ(one.model->predict(probe.x), two.model->predict(probe.x));
  ASSERT_EQ(one.curve.size(), 5u);  // the starting policy, then 2 windows x 2 iterations
  ASSERT_EQ(two.curve.size(), 5u);
  // Two targets of 60 steps: every iteration corrects steps 0..58 of each once, so the data
  // grows by 2 x 59 rows per iteration (re-adding earlier corrections would grow it faster).
  EXPECT_EQ(one.curve[0].dataset_rows, 120u);
  for (std::size_t k = 1; k < one.curve.size(); ++k) {
    EXPECT_EQ(one.curve[k].dataset_rows - one.curve[k - 1].dataset_rows, 118u) << "iteration " << k;
    EXPECT_EQ(one.curve[k].deviation, two.curve[k].deviation);
    EXPECT_EQ(one.curve[k].window, k <= 2 ? 1 : 2);
  }
}

TEST(Dad, KeepsThePolicyThatFollowsTheDemonstrationsBest) {
  const LearnResult r = LearnerRegistry::global().create("dad", kSmall)->learn(dad_context(2));
  const auto best = std::min_element(r.curve.begin(), r.curve.end(),
                                     [](const CurvePoint& a, const CurvePoint& b) { return a.deviation < b.deviation; });
  EXPECT_EQ(r.model->record.at("dad_iteration"), std::to_string(best->iteration));
}

TEST(Dad, ResumeEqualsUninterrupted) {
  const auto dir = test::scratch_path("dicestack_dad_resume");
  std::filesystem::remove_all(dir);
  LearnContext c = dad_context(2);
  const LearnResult whole = LearnerRegistry::global().create("dad", kSmall)->learn(c);
  // Killed when iteration 3 starts, then resumed.
  c.checkpoint_dir = dir;
  c.progress = [](const Progress& p) {
    if (p.iteration == 3) throw std::runtime_error("killed");
  };
  EXPECT_THROW(LearnerRegistry::global().create("dad", kSmall)->learn(c), std::runtime_error);
  // As if killed after writing iteration 3's data but before its state: the state still names
  // iteration 2's data, and the stray folder is not read.
  std::filesystem::copy(dir / "data-2", dir / "data-3", std::filesystem::copy_options::recursive);
  c.progress = nullptr;
  c.resume = true;
  const LearnResult resumed = LearnerRegistry::global().create("dad", kSmall)->learn(c);
  const Dataset probe = make_dataset(demos());
  EXPECT_EQ(resumed.model->predict(probe.x), whole.model->predict(probe.x));
  ASSERT_EQ(resumed.curve.size(), whole.curve.size());
  for (std::size_t k = 0; k < whole.curve.size(); ++k) EXPECT_EQ(resumed.curve[k].deviation, whole.curve[k].deviation);
  EXPECT_EQ(resumed.model->record.at("dad_iteration"), whole.model->record.at("dad_iteration"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dicestack
