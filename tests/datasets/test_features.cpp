#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/features.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

State numbered(double base) {
  State s;
  for (std::size_t j = 0; j < kStateDim; ++j) s[j] = base + static_cast<double>(j);
  return s;
}

std::vector<double> row_of(const FeatureMap& m, const History& h) {
  std::vector<double> out(m.width(), -999.0);
  m.compute(h, out);
  return out;
}

TEST(Features, StateClockStartOnAHandMadeHistory) {
  // Start: cup x = 100, dice x = 103, 109, 115 (mean 109); the current state is the third.
  const std::vector<State> states{numbered(100), numbered(200), numbered(300)};
  const std::vector<Action> actions{{1, 2, 3}, {4, 5, 6}};
  const History h{states, actions};
  const FeatureMap& m = feature_map("state+clock+start");
  ASSERT_EQ(m.width(), 27u);
  const auto row = row_of(m, h);
  for (std::size_t j = 0; j < kStateDim; ++j) EXPECT_EQ(row[j], 300.0 + static_cast<double>(j));
  EXPECT_EQ(row[24], 2.0);    // t
  EXPECT_EQ(row[25], 100.0);  // the start's cup x
  EXPECT_EQ(row[26], 109.0);  // the start's mean die x
  EXPECT_EQ(m.column_names()[24], "t");
  EXPECT_EQ(m.column_names().size(), m.width());
}

TEST(Features, StartStateCarriesTheWholeStart) {
  const std::vector<State> states{numbered(100), numbered(200)};
  const FeatureMap& m = feature_map("state+clock+start_state");
  ASSERT_EQ(m.width(), 49u);
  const auto row = row_of(m, History{states, {}});
  EXPECT_EQ(row[0], 200.0);
  EXPECT_EQ(row[24], 1.0);
  for (std::size_t j = 0; j < kStateDim; ++j) EXPECT_EQ(row[25 + j], 100.0 + static_cast<double>(j));
  EXPECT_EQ(m.column_names()[25], "start_cup_x");
}

TEST(Features, OpenLoopSeesTheClockAndTheStartButNeverTheCurrentState) {
  const FeatureMap& m = feature_map("clock+start_state");
  ASSERT_EQ(m.width(), 25u);
  const std::vector<State> a{numbered(100), numbered(200)}, b{numbered(100), numbered(900)};
  const auto row = row_of(m, History{a, {}});
  EXPECT_EQ(row, row_of(m, History{b, {}})) << "the current state changes nothing";
  EXPECT_EQ(row[0], 1.0);
  for (std::size_t j = 0; j < kStateDim; ++j) EXPECT_EQ(row[1 + j], 100.0 + static_cast<double>(j));
  EXPECT_EQ(m.column_names()[0], "t");
  EXPECT_EQ(m.column_names()[1], "start_cup_x");
}

TEST(Features, CupFeedbackSeesTheCupButNotTheDice) {
  const FeatureMap& m = feature_map("cup+clock+start_state");
  ASSERT_EQ(m.width(), 31u);
  std::vector<State> a{numbered(100), numbered(200)};
  const auto row = row_of(m, History{a, {}});
  EXPECT_EQ(row[0], 200.0);   // cup x
  EXPECT_EQ(row[5], 223.0);   // cup angular velocity
  EXPECT_EQ(row[6], 1.0);     // t
  EXPECT_EQ(row[7], 100.0);   // start cup x
  EXPECT_EQ(m.column_names()[3], "cup_vx");
  a[1][state_index::die(0)] += 5.0;  // a die moves: the row does not
  EXPECT_EQ(row_of(m, History{a, {}}), row);
}

TEST(Features, HistoryRepeatsTheStartAtStepZero) {
  const FeatureMap& m = feature_map("state+history");
  ASSERT_EQ(m.width(), 48u);
  const std::vector<State> one{numbered(10)}, two{numbered(10), numbered(50)};
  const auto at0 = row_of(m, History{one, {}});
  const auto at1 = row_of(m, History{two, {}});
  for (std::size_t j = 0; j < kStateDim; ++j) {
    EXPECT_EQ(at0[kStateDim + j], 10.0 + static_cast<double>(j));
    EXPECT_EQ(at1[j], 50.0 + static_cast<double>(j));
    EXPECT_EQ(at1[kStateDim + j], 10.0 + static_cast<double>(j));
  }
}

TEST(Features, StateAndClockWidths) {
  EXPECT_EQ(feature_map("state").width(), kStateDim);
  EXPECT_EQ(feature_map("state+clock").width(), kStateDim + 1);
  for (const auto& n : feature_map_names()) EXPECT_LE(feature_map(n).width(), kMaxFeatureWidth) << n;
  try {
    feature_map("state+clok");
    FAIL() << "an unknown map was accepted";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown feature map \"state+clok\"; known: state, state+clock"));
  }
}

TEST(Features, DatasetRowsSeeEachStepsOwnHistory) {
  Episode e;
  e.name = "episode_0000";
  e.states = {numbered(0), numbered(1), numbered(2)};
  e.actions = {{0.1, 0, 0}, {0.2, 0, 0}, {0.3, 0, 0}};
  e.sources.assign(3, StepSource::expert);
  const Dataset d = make_dataset({e}, feature_map("state+clock+start"));
  ASSERT_EQ(d.x.cols(), 27);
  for (Eigen::Index t = 0; t < 3; ++t) {
    EXPECT_EQ(d.x(t, 0), static_cast<double>(t));  // the current cup x
    EXPECT_EQ(d.x(t, 24), static_cast<double>(t)); // the clock
    EXPECT_EQ(d.x(t, 25), 0.0);                    // the start's cup x
  }
  EXPECT_EQ(make_dataset({e}).x.cols(), 24);  // "state" by default
}

TEST(Features, AVelocityMapSeesTheSameRowAndAnswersTheCupVelocityToSet) {
  const FeatureMap& base = feature_map("state+clock+start_state");
  const FeatureMap& v = feature_map("state+clock+start_state/velocity");
  EXPECT_EQ(v.name(), "state+clock+start_state/velocity");
  EXPECT_EQ(base.target(), ActionTarget::impulse);
  EXPECT_EQ(v.target(), ActionTarget::velocity);
  const std::vector<State> states{numbered(100), numbered(200)};
  EXPECT_EQ(row_of(v, History{states, {}}), row_of(base, History{states, {}}));
  EXPECT_EQ(v.column_names(), base.column_names());
  // numbered(200): cup vx, vy, w = 221, 222, 223.
  const Action a{0.5, -1.0, 2.0};
  std::array<double, kActionDim> label{};
  v.label(states[1], a, label);
  EXPECT_EQ(label, (std::array<double, kActionDim>{221.5, 221.0, 225.0}));
  EXPECT_EQ(v.action(states[1], label), a) << "answer and label invert each other";
  base.label(states[1], a, label);
  EXPECT_EQ(label, (std::array<double, kActionDim>{0.5, -1.0, 2.0})) << "an impulse map answers the action";
  for (const auto& n : feature_map_names()) {
    if (n.ends_with(kVelocityTargetSuffix)) continue;
    EXPECT_EQ(feature_map(n + std::string(kVelocityTargetSuffix)).width(), feature_map(n).width()) << n;
  }
}

TEST(Features, DatasetLabelsOfAVelocityMapAreTheCupVelocityEachStepSets) {
  Episode e;
  e.name = "episode_0000";
  e.states = {numbered(0), numbered(1)};
  e.actions = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}};
  e.sources.assign(2, StepSource::expert);
  const Dataset d = make_dataset({e}, feature_map("state/velocity"));
  for (Eigen::Index t = 0; t < 2; ++t)
    for (Eigen::Index k = 0; k < 3; ++k)
      EXPECT_DOUBLE_EQ(d.y(t, k), e.states[static_cast<std::size_t>(t)][21 + static_cast<std::size_t>(k)] +
                                      e.actions[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)]);
}

}  // namespace
}  // namespace dicestack
