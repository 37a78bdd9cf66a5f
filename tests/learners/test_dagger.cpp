// DAgger: beta 1 lets only the expert act, beta 0 the learner; results do not depend on the
// threads, and a resumed run equals an uninterrupted one.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/learner.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using test::small_context;

TEST(Dagger, BetaOneOnlyLetsTheExpertAct) {
  LearnContext c = small_context(2);
  const auto learner = LearnerRegistry::global().create(
      "dagger", {"iterations=1", "rollouts=3", "beta=1", "include_demos=false", "expert=scripted"});
  c.checkpoint_dir = test::scratch_path("dicestack_dagger_beta1");
  std::filesystem::remove_all(c.checkpoint_dir);
  const LearnResult r = learner->learn(c);
  // The options as the run used them, retry resolved for the map ("state": no retries).
  EXPECT_EQ(r.model->record.at("dagger_settings"),
            "iterations=1, rollouts=3, beta=1, schedule=exponential, expert=scripted, replan=true, retry=false, "
            "include_demos=false");
  const DemoSet data = read_demo_set(c.checkpoint_dir / "data-1");
  ASSERT_EQ(data.episodes.size(), 3u);
  for (const auto& e : data.episodes)
    for (auto s : e.sources) ASSERT_EQ(s, StepSource::expert);
  // The expert's own episodes from the same starts: the labels are exactly its actions.
  DiceEnv env(c.world);
  auto expert = make_expert("scripted");
  const std::uint64_t seed = training_start_seed(derive_seed(c.seed, 1), 0);
  env.reset_to(random_start_state(c.world, seed), seed);
  expert->reset(seed);
  const ExpertEpisode run = run_expert_episode(*expert, env, true);
  EXPECT_EQ(data.episodes[0].actions, run.actions);
  std::filesystem::remove_all(c.checkpoint_dir);
}

TEST(Dagger, LearnerActsWhenBetaIsZeroAndResultsIgnoreThreads) {
  const std::vector<std::string> opts{"iterations=2", "rollouts=3", "beta=0", "expert=scripted"};
  const DemoSet demos = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good");
  LearnContext one = small_context(1), two = small_context(2);
  one.demos = two.demos = demos.episodes;
  const LearnResult a = LearnerRegistry::global().create("dagger", opts)->learn(one);
  const LearnResult b = LearnerRegistry::global().create("dagger", opts)->learn(two);
  const Dataset probe = make_dataset(demos.episodes);
  EXPECT_EQ(a.model->predict(probe.x), b.model->predict(probe.x));
  ASSERT_EQ(a.curve.size(), 2u);
  EXPECT_EQ(a.curve[1].dataset_rows, b.curve[1].dataset_rows);
  EXPECT_GT(a.curve[1].dataset_rows, a.curve[0].dataset_rows);
}

TEST(Dagger, ResumeEqualsUninterrupted) {
  const DemoSet demos = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good");
  LearnContext c = small_context(2);
  c.demos = demos.episodes;
  const auto dir = test::scratch_path("dicestack_dagger_resume");
  std::filesystem::remove_all(dir);
  const LearnResult whole = LearnerRegistry::global().create("dagger", {"iterations=3", "rollouts=2", "expert=scripted"})->learn(c);
  // Run two rounds (as if killed after round 2), then resume to three.
  c.checkpoint_dir = dir;
  LearnerRegistry::global().create("dagger", {"iterations=2", "rollouts=2", "expert=scripted"})->learn(c);
  c.resume = true;
  const LearnResult resumed = LearnerRegistry::global().create("dagger", {"iterations=3", "rollouts=2", "expert=scripted"})->learn(c);
  const Dataset probe = make_dataset(demos.episodes);
  EXPECT_EQ(resumed.model->predict(probe.x), whole.model->predict(probe.x));
  ASSERT_EQ(resumed.curve.size(), 3u);
  EXPECT_EQ(resumed.curve.back().dataset_rows, whole.curve.back().dataset_rows);
  // Resuming with other options is refused, naming the setting and both values.
  const std::string error = test::error_of([&] {
    LearnerRegistry::global().create("dagger", {"iterations=4", "rollouts=3", "expert=scripted"})->learn(c);
  });
  EXPECT_THAT(error, ::testing::HasSubstr(
                         "dagger.json: cannot resume a run made with other settings: option rollouts \"2\" in the "
                         "checkpoint, \"3\" in this run"));
  c.seed += 1;
  EXPECT_THAT(test::error_of([&] {
                LearnerRegistry::global().create("dagger", {"iterations=4", "rollouts=2", "expert=scripted"})->learn(c);
              }),
              ::testing::HasSubstr("seed \"11\" in the checkpoint, \"12\" in this run"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dicestack
