// Feature maps of a policy on the arm: the links its joint encoders read, and answers in joint
// torques.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vector>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/features.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

constexpr const char* kTorqueMap = "state+links+clock+start_state@dice+retry/torque";

State counted(double base) {
  State s;
  for (std::size_t j = 0; j < kStateDim; ++j) s[j] = base + static_cast<double>(j);
  return s;
}

TEST(ArmFeatures, TheLinksPartReadsTheCurrentLinksAfterTheState) {
  const std::vector<State> states{counted(0), counted(100)};
  const std::vector<ArmLinks> links{{{1, 2, 3}, {4, 5, 6}}, {{7, 8, 9}, {10, 11, 12}}};
  const FeatureMap& m = feature_map("state+links+clock");
  ASSERT_EQ(m.width(), kStateDim + 6 + 1);
  EXPECT_TRUE(m.reads_links());
  std::vector<double> row(m.width());
  m.compute(History{states, {}, {}, {}, links}, row);
  EXPECT_EQ(std::vector<double>(row.begin() + kStateDim, row.end()), (std::vector<double>{7, 8, 9, 10, 11, 12, 1}));
  const auto names = m.column_names();
  EXPECT_EQ(names[kStateDim], "link0_angle");
  EXPECT_EQ(names[kStateDim + 5], "link2_rate");
  EXPECT_EQ(names.size(), m.width());
  // Without readings (a floating cup's episode) the row cannot be made: said, not guessed.
  EXPECT_THAT(test::error_of([&] { m.compute(History{states, {}}, row); }), HasSubstr("reads the arm's links"));
}

TEST(ArmFeatures, ATorqueMapAnswersTheFourTorquesAsTheyAre) {
  const FeatureMap& m = feature_map(kTorqueMap);
  EXPECT_EQ(m.name(), kTorqueMap);
  EXPECT_EQ(m.action_kind(), ActionKind::joint_torque);
  EXPECT_EQ(m.outputs(), kJointCount);
  EXPECT_EQ(feature_map("state").outputs(), kActionDim);
  const std::vector<State> states{counted(0)};
  const std::vector<ArmLinks> links(1);
  const History h{states, {}, {}, {}, links};
  const Action torques = Action::torques({100, -50, 20, -5});
  std::vector<double> label(m.outputs());
  m.label(h, torques, label);
  EXPECT_EQ(label, (std::vector<double>{100, -50, 20, -5}));
  EXPECT_EQ(m.action(h, label), torques);
  // A cup action is no label for it, nor a torque for a cup map.
  EXPECT_THAT(test::error_of([&] { m.label(h, Action{1, 2, 3}, label); }), HasSubstr("answers joint_torque actions"));
  std::vector<double> three(3);
  EXPECT_THAT(test::error_of([&] { feature_map("state").label(h, torques, three); }), HasSubstr("answers cup actions"));
}

TEST(ArmFeatures, TorqueMapsTakeNoTimingAndRunOnlyOnTheArm) {
  EXPECT_THAT(test::error_of([] { feature_map("state+links/torque/ahead"); }), HasSubstr("takes no timing"));
  EXPECT_THAT(test::error_of([] { feature_map("links+state/torque"); }), HasSubstr("must come before"));
  EXPECT_EQ(to_string(parse_feature_spec("cup+links+clock/torque")), "cup+links+clock/torque");
  WorldConfig world;
  EXPECT_THAT(test::error_of([&] { check_map_world(feature_map(kTorqueMap), world); }), HasSubstr("--embodiment arm"));
  EXPECT_THAT(test::error_of([&] { check_map_world(feature_map("state+links"), world); }), HasSubstr("reads the arm's links"));
  world.embodiment = Embodiment::arm;
  EXPECT_NO_THROW(check_map_world(feature_map(kTorqueMap), world));
}

// An "/osc" map answers the cup pose whose servo velocity the operational-space law turns into
// the torques: a teacher's torques within the limits are labelled and given back as they were.
TEST(ArmFeatures, AnOscMapAnswersThePoseTheLawTurnsBackIntoTheTorques) {
  WorldConfig c;
  c.embodiment = Embodiment::arm;
  State lifted = paper_start_state(c);
  lifted[state_index::kCupY] += 1.5;
  lifted[state_index::kCupVx] = 0.3;
  const World w(c, lifted);
  const std::vector<State> states{w.state()};
  const std::vector<ArmLinks> links{{w.arm_link_angles(), w.arm_link_rates()}};
  const History h{states, {}, {}, {}, links};
  const FeatureMap& m = feature_map("state+links+clock+start_state@dice/osc");  // x from the dice's mean
  EXPECT_EQ(m.action_kind(), ActionKind::joint_torque);
  EXPECT_EQ(m.outputs(), kActionDim + 1) << "a pose and the posture, not four torques";
  EXPECT_EQ(m.answer_names().back(), "posture");
  EXPECT_EQ(m.width(), feature_map("state+links+clock+start_state@dice").width());
  ASSERT_GT(m.origin_x(h), 1.0);
  const std::array<double, 4> taught = arm_torques(c.arm, w.arm_motion(), {0.5, 0.2}, 0.3, c.physics.control_dt, c.physics.gravity, -1.5);
  std::vector<double> label(m.outputs());
  m.label(h, Action::torques(taught), label);
  EXPECT_NEAR(label[0], states[0][state_index::kCupX] + 0.5 / kPositionGain - m.origin_x(h), 1e-9);
  EXPECT_NEAR(label[1], states[0][state_index::kCupY] + 0.2 / kPositionGain, 1e-9);
  EXPECT_NEAR(label[2], states[0][state_index::kCupAngle] + 0.3 / kPositionGain, 1e-9);
  EXPECT_NEAR(label[3], -1.5, 1e-9);
  const Action back = m.action(h, label);
  ASSERT_EQ(back.kind(), ActionKind::joint_torque);
  for (std::size_t j = 0; j < kJointCount; ++j) EXPECT_NEAR(back[j], taught[j], 1e-6 * c.arm.torque_limit[j]) << j;
}

TEST(ArmFeatures, AnOscMapNeedsTheLinksAndTheDefaultArm) {
  EXPECT_THAT(test::error_of([] { feature_map("state+clock/osc"); }), HasSubstr("give links among its parts"));
  EXPECT_THAT(test::error_of([] { feature_map("state+links/osc/ahead"); }), HasSubstr("takes no timing"));
  const std::vector<State> states{counted(0)};
  std::vector<double> label(4);
  EXPECT_THAT(test::error_of([&] { feature_map("state+links/osc").label(History{states, {}}, Action::torques({1, 2, 3, 4}), label); }),
              HasSubstr("no readings of them"));
  WorldConfig world;
  world.embodiment = Embodiment::arm;
  EXPECT_NO_THROW(check_map_world(feature_map("state+links/osc"), world));
  world.arm.link_lengths[0] += 0.1;
  EXPECT_THAT(test::error_of([&] { check_map_world(feature_map("state+links/osc"), world); }),
              HasSubstr("default world's arm and control step"));
}

TEST(ArmFeatures, DatasetRowsOfATorqueMapComeFromTheEpisodesLinksAndTorques) {
  Episode e;
  e.name = "arm";
  for (int t = 0; t < 3; ++t) {
    e.states.push_back(counted(10.0 * t));
    e.links.push_back({{0.1 * t, 0.2, 0.3}, {0.0, 0.0, 1.0 * t}});
    e.actions.push_back(Action::torques({1.0 * t, 2, 3, 4}));
    e.sources.push_back(StepSource::expert);
  }
  const Dataset d = make_dataset({e}, feature_map("state+links/torque"));
  ASSERT_EQ(d.y.cols(), 4);
  EXPECT_EQ(d.y(2, 0), 2.0);
  EXPECT_EQ(d.x(2, kStateDim), 0.2);       // link0_angle at t = 2
  EXPECT_EQ(d.x(2, kStateDim + 5), 2.0);   // link2_rate at t = 2
  e.links.pop_back();
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, feature_map("state+links/torque")); }),
              HasSubstr("3 states and 2 arm link readings"));
}

}  // namespace
}  // namespace dicestack
