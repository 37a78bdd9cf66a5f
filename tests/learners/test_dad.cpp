#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/corrector.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/demos.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using test::demos;

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

TEST(Dad, FaithfulIsTrueFalseOrPartsOfThePapersCodeAndAnythingElseIsRefusedByPart) {
  for (const char* ok : {"faithful=true", "faithful=false", "faithful=start", "faithful=label+cost+duplicates"})
    EXPECT_NO_THROW(LearnerRegistry::global().create("dad", {ok})) << ok;
  const std::string error =
      test::error_of([] { LearnerRegistry::global().create("dad", {"faithful=start+labels"}); });
  EXPECT_THAT(error, ::testing::HasSubstr("unknown part \"labels\""));
  EXPECT_THAT(error, ::testing::HasSubstr("start, label, cost, schedule, search, duplicates, units"));
  EXPECT_THROW(LearnerRegistry::global().create("dad", {"faithful=start+"}), ConfigError);
  EXPECT_THAT(test::error_of([] { LearnerRegistry::global().create("dad", {"faithful=" + std::string(5000, 'x')}); }).size(),
              ::testing::Lt(400u));  // a long value is not echoed whole
}

TEST(Dad, TheCodesDuplicatesAppendEveryCorrectionAgainAtEachRefit) {
  // One-step labels at each of the 59 steps of 2 targets: 118 new corrections per iteration;
  // with the code's duplicates, a refit after iteration k fits those of iteration j k - j + 1 times.
  const std::vector<std::string> options{"windows=1", "iterations=3", "corrector_iterations=1", "demos=2",
                                         "faithful=label+duplicates"};
  const LearnResult r = LearnerRegistry::global().create("dad", options)->learn(dad_context(2));
  ASSERT_EQ(r.curve.size(), 4u);
  for (std::size_t k = 0; k < r.curve.size(); ++k) EXPECT_EQ(r.curve[k].dataset_rows, 120u + 118u * k * (k + 1) / 2) << k;
  const LearnResult once = LearnerRegistry::global().create("dad", {"windows=1", "iterations=3", "corrector_iterations=1",
                                                                     "demos=2", "faithful=label"})->learn(dad_context(2));
  for (std::size_t k = 0; k < once.curve.size(); ++k) EXPECT_EQ(once.curve[k].dataset_rows, 120u + 118u * k) << k;
}

TEST(Dad, TheCodesScheduleCorrectsGrowingPrefixesFiveTimesEachAndKeepsTheLastRefit) {
  const std::vector<std::string> options{"corrector_iterations=1", "demos=2", "faithful=schedule+label"};
  const LearnResult r = LearnerRegistry::global().create("dad", options)->learn(dad_context(2));
  ASSERT_EQ(r.curve.size(), 51u);  // 10 prefixes x 5 refits
  for (std::size_t k = 1; k < r.curve.size(); ++k) {
    const std::size_t window = (k - 1) / 5 + 1;
    EXPECT_EQ(r.curve[k].window, static_cast<int>(window));
    // The first 6 window steps of each 60-step target (the last prefix: its 59 steps with a next state).
    EXPECT_EQ(r.curve[k].dataset_rows - r.curve[k - 1].dataset_rows, 2 * std::min<std::size_t>(59, 6 * window)) << k;
  }
  EXPECT_EQ(r.model->record.at("dad_iteration"), "50");
  EXPECT_EQ(r.model->record.at("dad_faithful"), "schedule+label");
  // The options as the run used them: the code's schedule (10 windows of 5 refits) over the given ones.
  EXPECT_THAT(r.model->record.at("dad_settings"), testing::StartsWith("windows=10, iterations=5, target=cup, corrector=cmaes"));
  EXPECT_THAT(r.model->record.at("dad_settings"), testing::EndsWith("starts=demonstrations, demos=2, episodes=300, retry=false"));
}

TEST(Dad, AWindowCarriesTheRolloutBeforeItAsHistoryForAMapThatReadsTheEpisode) {
  const auto dir = test::scratch_path("dicestack_dad_history");
  std::filesystem::remove_all(dir);
  LearnContext c = dad_context(2);
  c.checkpoint_dir = dir;
  c.features = "state+clock+start_state";
  const LearnResult r = LearnerRegistry::global()
                            .create("dad", {"windows=2", "iterations=1", "corrector_iterations=1", "demos=2", "filter=false"})
                            ->learn(c);
  // As with the bare state: 59 corrected steps of each target, the rollout before a window not a row.
  ASSERT_EQ(r.curve.size(), 3u);
  EXPECT_EQ(r.curve[1].dataset_rows - r.curve[0].dataset_rows, 118u);
  EXPECT_EQ(r.curve[2].dataset_rows - r.curve[1].dataset_rows, 118u);
  const DemoSet data = read_demo_set(dir / "data-2");
  std::size_t windows = 0;
  for (const auto& e : data.episodes) {
    const std::size_t from = e.origin.find(" from step ");
    if (e.origin.rfind("dad iteration ", 0) != 0 || from == std::string::npos) continue;
    ++windows;
    const std::size_t t = std::stoul(e.origin.substr(from + 11));
    ASSERT_GT(e.size(), t) << e.origin;
    for (std::size_t k = 0; k < e.size(); ++k) EXPECT_EQ(e.sources[k], k < t ? StepSource::policy : StepSource::correction);
    // It starts where a target's rollout started (the targets are two of the three demonstrations).
    auto from_target = [&](const Episode& target) {
      for (std::size_t k = 0; k < kStateDim; ++k)
        if (std::abs(e.states[0][k] - target.states[0][k]) > 1e-6) return false;
      return true;
    };
    EXPECT_TRUE(std::any_of(demos().begin(), demos().end(), from_target)) << e.origin;
  }
  EXPECT_GE(windows, 2u);
  std::filesystem::remove_all(dir);
}

// DaD's data after its first refit (the checkpoint's `data-1`), trained in a scratch folder.
DemoSet first_round_data(LearnContext c, const std::string& scratch, const std::vector<std::string>& options) {
  const auto dir = test::scratch_path(scratch);
  std::filesystem::remove_all(dir);
  c.checkpoint_dir = dir;
  LearnerRegistry::global().create("dad", options)->learn(c);
  DemoSet data = read_demo_set(dir / "data-1");
  std::filesystem::remove_all(dir);
  return data;
}

TEST(Dad, TheCodesUnitsLabelACorrectionWithTheOptimisersVariableInTheRecordingsUnits) {
  const LearnContext c = dad_context(1);
  const DemoSet data = first_round_data(
      c, "dicestack_dad_units", {"windows=1", "iterations=1", "corrector_iterations=2", "demos=1", "filter=false", "faithful=units"});
  ASSERT_EQ(data.episodes.size(), 2u);  // the target, then its one window
  const Episode& fix = data.episodes[1];
  // Undone, the label is the action the corrector found: replayed, it gives the window's next state.
  DiceEnv env(c.world);
  env.reset_to(fix.states[0], fix.seed);
  const Action found{fix.actions[0][0] / 0.01, fix.actions[0][1] / 0.1, fix.actions[0][2] / 2.0};
  env.step(found);
  for (std::size_t k = 0; k < kStateDim; ++k) EXPECT_NEAR(env.get_state()[k], fix.states[1][k], 1e-5) << k;
}

TEST(Dad, TheCodesRolloutsStartFromTheOneFixedStartAndItsOneStepLabelsReadAnyFeatureMap) {
  LearnContext c = dad_context(2);
  c.features = "state+clock+start_state";
  const DemoSet data = first_round_data(c, "dicestack_dad_fixed_start",
                                        {"windows=1", "iterations=1", "corrector_iterations=1", "demos=2", "faithful=start+label"});
  ASSERT_EQ(data.episodes.size(), 4u);  // the 2 targets, then one labelled rollout towards each
  for (std::size_t i = 2; i < 4; ++i) {
    const State start = paper_start_state(c.world);  // as Box2D holds it: in single precision
    for (std::size_t k = 0; k < kStateDim; ++k) EXPECT_NEAR(data.episodes[i].states[0][k], start[k], 1e-6) << i << " " << k;
    EXPECT_EQ(data.episodes[i].size(), 59u);
    EXPECT_EQ(data.episodes[i].sources[0], StepSource::correction);
  }
}

}  // namespace
}  // namespace dicestack
