// `train --controller`: the map a request trains, in the arm's joint torques or the cup's actions,
// and the requests that cannot train such a policy, refused before any demonstration is read.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/experiments/train.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

TrainRequest torque_request() {
  TrainRequest r;
  r.world.embodiment = Embodiment::arm;
  r.regressor = "gbt";
  r.learner = "dart";
  r.learner_options = {"expert=tracker"};
  r.controller = "joint_torque";
  return r;
}

TEST(TrainController, JointTorquesTakeTheLearnersMapInTorques) {
  EXPECT_EQ(check_train_settings(torque_request()), "state+links+clock+start_state@dice+retry/osc");
  EXPECT_EQ(torque_map_name("state+clock/position/ahead"), "state+links+clock/osc");
  TrainRequest cup = torque_request();
  cup.controller = "cup";
  EXPECT_EQ(check_train_settings(cup), "state+clock+start_state@dice+retry/position");
}

TEST(TrainController, AMapOrLearnerOrWorldThatCannotIsRefused) {
  TrainRequest r = torque_request();
  r.features = "state+clock/position";
  EXPECT_THAT(test::error_of([&] { check_train_settings(r); }), HasSubstr("answers cup actions, not the joint_torque controller's"));
  r = torque_request();
  r.learner = "dad";
  r.learner_options = {};
  EXPECT_THAT(test::error_of([&] { check_train_settings(r); }), HasSubstr("give it starts=training"));
  r.learner_options = {"starts=training", "corrector=track"};
  EXPECT_EQ(check_train_settings(r), "state+links+clock+start_state@dice+retry/osc");
  r.learner_options = {};
  r.learner = "bc";  // from episodes recorded on the arm, which the dataset checks when it fits
  r.features = "state+links+clock+start_state@dice+retry/osc";
  EXPECT_EQ(check_train_settings(r), r.features);
  r = torque_request();
  r.world.embodiment = Embodiment::cup;
  EXPECT_THAT(test::error_of([&] { check_train_settings(r); }), HasSubstr("--embodiment arm"));
  // A leaderboard's row of the arm's links: learned as `train` learns it (DART; DaD only from
  // training starts).
  const LearnerInfo& dart = LearnerRegistry::global().info("dart");
  EXPECT_NO_THROW(require_labellable(dart.params, Params(dart.params, {}, "dart"), r.world,
                                     feature_map("state+links+clock/torque"), "dart"));
  const LearnerInfo& dad = LearnerRegistry::global().info("dad");
  EXPECT_THAT(test::error_of([&] {
                require_labellable(dad.params, Params(dad.params, {}, "dad"), r.world,
                                   feature_map("state+links+clock/torque"), "dad");
              }),
              HasSubstr("give it starts=training"));
  r = torque_request();
  r.controller = "wrist";
  EXPECT_THAT(test::error_of([&] { check_train_settings(r); }), HasSubstr("is not one of cup, joint_torque"));
}

}  // namespace
}  // namespace dicestack
