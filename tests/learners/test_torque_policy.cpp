// A policy in joint torques on the arm: DART taught by the tracker told in torques, its model
// reading the arm's links, rolled out with only the regressor acting.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/policy.hpp>

#include <dicestack/test/demos.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr const char* kTorqueMap = "state+links+clock+start_state@dice+retry/torque";

// The tracker in its cheapest form: one probe, no variants (and, in torques, no refinement).
std::vector<std::string> quick_dart(std::vector<std::string> more = {}) {
  std::vector<std::string> out{"expert=tracker",   "episodes=2",       "successes_only=false",
                               "tracker_probes=1", "tracker_robust=1", "tracker_variants=false"};
  out.insert(out.end(), more.begin(), more.end());
  return out;
}

LearnContext arm_context() {
  LearnContext c;
  c.world = test::short_world(40);
  c.world.embodiment = Embodiment::arm;
  c.demos = test::human_six();
  c.demos.resize(2);
  c.regressor = "knn";
  c.features = kTorqueMap;
  c.seed = 4;
  c.threads = 1;
  return c;
}

TEST(TorquePolicy, DartLearnsTheTrackersTorquesTheSameOnAnyThreadCount) {
  LearnContext c = arm_context();
  const auto learner = LearnerRegistry::global().create("dart", quick_dart());
  const LearnResult one = learner->learn(c);
  c.threads = 2;
  const LearnResult two = learner->learn(c);
  EXPECT_EQ(one.model->regressor().save_payload(), two.model->regressor().save_payload());
  EXPECT_EQ(one.model->features().action_kind(), ActionKind::joint_torque);
  // In torques DART's noise and the tracker's refinement have their own defaults.
  EXPECT_THAT(one.model->record.at("dart_settings"), HasSubstr("noise=0.001/0.001/0.001/0.001"));
  EXPECT_THAT(one.model->record.at("tracker_settings"), HasSubstr("refine=0,"));

  // Rolled out on the arm, the regressor alone answers torques; the episode keeps the links it read.
  DiceEnv env(c.world);
  ModelPolicy policy(one.model);
  const std::uint64_t seed = 17;
  const Episode e = rollout(env, policy, random_start_state(c.world, seed), seed, StepSource::policy);
  ASSERT_EQ(e.links.size(), e.states.size());
  EXPECT_EQ(e.actions.front().kind(), ActionKind::joint_torque);
  EXPECT_NE(e.links.front(), e.links.back()) << "the arm moved";
}

// An "/osc" student answers the cup pose the law servos to and the posture's acceleration (four
// numbers, labelled through the law's inverse from the teacher's torques), and acts in joint
// torques.
TEST(TorquePolicy, DartLearnsAnOscMapWhoseRegressorAnswersAPoseAndActsInTorques) {
  LearnContext c = arm_context();
  c.features = "state+links+clock+start_state@dice+retry/osc";
  const LearnResult r = LearnerRegistry::global().create("dart", quick_dart())->learn(c);
  EXPECT_EQ(r.model->regressor().output_dim(), kActionDim + 1);
  EXPECT_THAT(r.model->record.at("dart_settings"), HasSubstr("noise=0.03/0.03/0.03/0.03"));
  EXPECT_THAT(r.model->record.at("tracker_settings"), HasSubstr("paths=1,")) << "one pose per step: one path, as /position";
  DiceEnv env(c.world);
  ModelPolicy policy(r.model);
  const Episode e = rollout(env, policy, random_start_state(c.world, 17), 17, StepSource::policy);
  EXPECT_EQ(e.actions.front().kind(), ActionKind::joint_torque);
  EXPECT_NE(e.links.front(), e.links.back()) << "the arm moved";
}

// Behaviour cloning in torques fits episodes recorded on the arm (their links and torques), and
// names an episode of the floating cup, which has neither.
TEST(TorquePolicy, BcFitsEpisodesRecordedOnTheArmAndNamesOneThatWasNot) {
  LearnContext c = arm_context();
  const LearnResult teacher = LearnerRegistry::global().create("dart", quick_dart())->learn(c);
  DiceEnv env(c.world);
  ModelPolicy policy(teacher.model);
  const Episode on_arm = rollout(env, policy, random_start_state(c.world, 17), 17, StepSource::policy);
  const auto bc = LearnerRegistry::global().create("bc", {});
  EXPECT_THAT(test::error_of([&] { bc->learn(c); }),
              AllOf(HasSubstr("\"" + c.demos.front().name + "\""), HasSubstr("record --embodiment arm --controller joint_torque")));
  c.demos = {on_arm};
  const LearnResult student = bc->learn(c);
  EXPECT_EQ(student.model->features().action_kind(), ActionKind::joint_torque);
  EXPECT_EQ(student.model->regressor().output_dim(), 4u);
}

// DAgger's rounds in torques: the student's own rollouts labelled by the tracker told in torques,
// kept in its checkpoint (episodes whose actions are joint torques) and resumed from it.
TEST(TorquePolicy, DaggerLearnsTheTrackersTorquesAndResumesFromItsCheckpoint) {
  LearnContext c = arm_context();
  const auto options = [](int iterations) {
    return std::vector<std::string>{"expert=tracker", "include_demos=false", "iterations=" + std::to_string(iterations),
                                    "rollouts=2", "tracker_probes=1", "tracker_robust=1", "tracker_variants=false"};
  };
  const LearnResult whole = LearnerRegistry::global().create("dagger", options(2))->learn(c);
  EXPECT_EQ(whole.model->features().action_kind(), ActionKind::joint_torque);
  c.checkpoint_dir = test::scratch_path("dicestack_dagger_torques");
  std::filesystem::remove_all(c.checkpoint_dir);
  LearnerRegistry::global().create("dagger", options(1))->learn(c);
  const DemoSet round = read_demo_set(c.checkpoint_dir / "data-1");
  ASSERT_FALSE(round.episodes.empty());
  EXPECT_EQ(round.episodes[0].actions.front().kind(), ActionKind::joint_torque);
  EXPECT_EQ(round.episodes[0].links.size(), round.episodes[0].size());
  c.resume = true;
  const LearnResult resumed = LearnerRegistry::global().create("dagger", options(2))->learn(c);
  EXPECT_EQ(resumed.model->regressor().save_payload(), whole.model->regressor().save_payload());
  std::filesystem::remove_all(c.checkpoint_dir);
}

// DaD on the arm: the tracker's targets in torques from training starts, each window of the
// policy's own rollout steered back by the feedback law told in torques. Its corrections keep the
// links they were made at, in its checkpoint too, and a resumed run on two threads ends where a
// whole one on one thread does.
TEST(TorquePolicy, DadCorrectsItsOwnRolloutsInTorquesAndResumesFromItsCheckpoint) {
  LearnContext c = arm_context();
  c.world = WorldConfig{};
  c.world.embodiment = Embodiment::arm;
  c.demos = test::human_six();
  c.demos.resize(3);
  c.features = "state+links+clock+start_state@dice+retry/osc";
  const std::vector<std::string> options{"starts=training", "episodes=2",      "windows=1",        "iterations=2",
                                         "corrector=track", "keep_best=false", "tracker_probes=1", "tracker_robust=1",
                                         "tracker_variants=false"};
  const LearnResult whole = LearnerRegistry::global().create("dad", options)->learn(c);
  EXPECT_EQ(whole.model->features().action_kind(), ActionKind::joint_torque);
  EXPECT_GT(std::stoi(whole.model->record.at("dad_corrections_kept")), 0);

  // Killed when iteration 2 starts, then resumed, on another thread count.
  c.threads = 2;
  c.checkpoint_dir = test::scratch_path("dicestack_dad_torques");
  std::filesystem::remove_all(c.checkpoint_dir);
  c.progress = [](const Progress& p) {
    if (p.iteration == 2) throw std::runtime_error("killed");
  };
  EXPECT_THROW(LearnerRegistry::global().create("dad", options)->learn(c), std::runtime_error);
  c.progress = nullptr;
  const DemoSet data = read_demo_set(c.checkpoint_dir / "data-1");
  const auto correction = std::find_if(data.episodes.begin(), data.episodes.end(),
                                       [](const Episode& e) { return e.origin.starts_with("dad iteration 1"); });
  ASSERT_NE(correction, data.episodes.end());
  EXPECT_EQ(correction->actions.back().kind(), ActionKind::joint_torque);
  EXPECT_EQ(correction->links.size(), correction->size());
  c.resume = true;
  const LearnResult resumed = LearnerRegistry::global().create("dad", options)->learn(c);
  EXPECT_EQ(resumed.model->regressor().save_payload(), whole.model->regressor().save_payload());
  std::filesystem::remove_all(c.checkpoint_dir);
}

TEST(TorquePolicy, WhatCannotLearnOrRunTorquesIsRefusedByName) {
  LearnContext c = arm_context();
  const auto refused = [&](const std::string& learner, const std::vector<std::string>& options) {
    return test::error_of([&] { LearnerRegistry::global().create(learner, options)->learn(c); });
  };
  EXPECT_THAT(refused("dart", quick_dart({"noise_dvy=0.5"})), HasSubstr("noise_dvy is a cup action's noise"));
  EXPECT_THAT(refused("dart", quick_dart({"include_demos=true"})), HasSubstr("include_demos adds recordings without"));
  EXPECT_THAT(refused("dart", quick_dart({"perturb=easy"})), HasSubstr("perturb= is not built for a policy of the arm's links"));
  EXPECT_THAT(refused("dagger", {"expert=tracker", "iterations=1", "rollouts=1"}), HasSubstr("include_demos adds recordings without"));
  const auto dad_refusal = [](const std::vector<std::string>& options) {
    return test::error_of([&] {
      require_learnable_map("dad", LearnerRegistry::global().create("dad", options)->params(), feature_map(kTorqueMap));
    });
  };
  EXPECT_THAT(dad_refusal({}), HasSubstr("give it starts=training"));
  EXPECT_THAT(dad_refusal({"starts=training"}), HasSubstr("give it corrector=track"));
  EXPECT_THAT(dad_refusal({"faithful=units"}), HasSubstr("faithful= runs the paper's code"));  // named first: it overrides the rest
  // DaD checks its map itself, before the tracker or a fit runs.
  EXPECT_THAT(refused("dad", {"corrector=track"}), HasSubstr("give it starts=training"));
  EXPECT_THAT(test::error_of([] {
                require_learnable_map("my_plugin", Params{}, feature_map(kTorqueMap));  // a plugin learner
              }),
              HasSubstr("or by dart, dagger and dad (starts=training, corrector=track)"));
  // Where torques cannot run, an evaluation refuses before any rollout.
  EvalRequest request;
  request.actions = ActionKind::joint_torque;
  EXPECT_THAT(test::error_of([&] { check_evaluation(WorldConfig{}, request); }), HasSubstr("give --embodiment arm"));
  request.push = InitialPush::left;
  EXPECT_THAT(test::error_of([&] { check_evaluation(c.world, request); }), HasSubstr("an initial push is a cup velocity change"));
}

TEST(TorquePolicy, AFloatingCupsRolloutKeepsNoLinks) {
  LearnContext c = arm_context();
  c.world.embodiment = Embodiment::cup;
  DiceEnv env(c.world);
  const auto expert = make_expert("scripted");
  ExpertPolicy scripted(*expert, env);
  const Episode e = rollout(env, scripted, random_start_state(c.world, 3), 3, StepSource::expert);
  EXPECT_TRUE(e.links.empty());
}

}  // namespace
}  // namespace dicestack
