#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/features.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

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
    EXPECT_THAT(e.what(), HasSubstr("feature map \"state+clok\": unknown part \"clok\""));
    EXPECT_THAT(e.what(), Not(HasSubstr("state+clock+start_state@dice/velocity"))) << "the part, not every name";
  }
}

TEST(FeatureSpec, EveryListedNameReadsBackAsItself) {
  for (const auto& n : feature_map_names()) {
    EXPECT_EQ(to_string(parse_feature_spec(n)), n);
    EXPECT_EQ(feature_map(n).name(), n);
    EXPECT_EQ(&feature_map(n), &feature_map(n)) << "one object per name: models keep a reference";
  }
  EXPECT_EQ(feature_map_names().size(), 99u);
}

TEST(FeatureSpec, ANameIsReadPartByPart) {
  const FeatureSpec f = parse_feature_spec("state+clock+start_state@dice+retry/position/landing");
  EXPECT_EQ(f.current, FeatureSpec::Current::state);
  EXPECT_TRUE(f.clock);
  EXPECT_EQ(f.start, FeatureSpec::Start::whole);
  EXPECT_TRUE(f.dice_frame);
  EXPECT_FALSE(f.previous);
  EXPECT_TRUE(f.restart);
  EXPECT_EQ(f.target, ActionTarget::position);
  EXPECT_EQ(f.timing, FeatureSpec::Timing::landing);
  const FeatureSpec open = parse_feature_spec("clock+start");
  EXPECT_EQ(open.current, FeatureSpec::Current::none);
  EXPECT_EQ(open.start, FeatureSpec::Start::summary);
  EXPECT_EQ(open.target, ActionTarget::impulse);
  EXPECT_EQ(open.timing, FeatureSpec::Timing::now);
}

TEST(FeatureSpec, AnyNameTheGrammarAllowsIsAMapWithItsPartsColumns) {
  // Not among the listed maps: the start and the previous state together, at the widest.
  const FeatureMap& m = feature_map("state+clock+start_state@dice+history/velocity");
  EXPECT_EQ(m.width(), 3 * kStateDim + 2);
  EXPECT_LE(m.width(), kMaxFeatureWidth);
  const auto columns = m.column_names();
  ASSERT_EQ(columns.size(), m.width());
  EXPECT_EQ(columns[kStateDim], "t");
  EXPECT_EQ(columns[kStateDim + 1], "start_" + std::string(state_names()[0]));
  EXPECT_EQ(columns[2 * kStateDim + 1], "prev_" + std::string(state_names()[0]));
  EXPECT_EQ(columns.back(), "origin_x");
  EXPECT_EQ(m.target(), ActionTarget::velocity);
  const std::vector<State> states{numbered(100), numbered(200)};
  const auto row = row_of(m, History{states, {}});
  const double x0 = mean_dice_x(states[0]);
  EXPECT_DOUBLE_EQ(row[kStateDim], 1.0);
  EXPECT_DOUBLE_EQ(row[kStateDim + 1 + state_index::kCupX], 100.0 - x0) << "the start, in the dice frame";
  EXPECT_DOUBLE_EQ(row[2 * kStateDim + 1 + state_index::kCupY], 101.0) << "the previous state is the start";
  EXPECT_DOUBLE_EQ(row.back(), x0);
  EXPECT_EQ(feature_map("clock").width(), 1u) << "nothing but the clock: open loop";
}

TEST(FeatureSpec, AWrongNameIsRefusedNamingThePartThatBreaksTheGrammar) {
  const auto error_of = [](const std::string& name) {
    try {
      parse_feature_spec(name);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::pair<const char*, const char*> cases[] = {
      {"state+tomorrow", "unknown part \"tomorrow\""},
      {"clock+state", "\"state\" must come before \"clock\""},
      {"state+cup", "\"cup\" after \"state\": give one of them"},
      {"state+clock+clock", "\"clock\" given twice"},
      {"state+start+start_state", "\"start_state\" after \"start\""},
      {"state@dice", "\"@dice\" follows start or start_state, not \"state\""},
      {"state+retry", "\"retry\" restarts the clock and the start"},
      {"state++clock", "an empty part"},
      {"", "an empty part"},
      {"state/", "unknown suffix \"/\""},
      {"state/speed", "unknown suffix \"/speed\""},
      {"state/ahead/velocity", "\"/velocity\" must come before the timing"},
      {"state/velocity/position", "\"/position\" given with another target"},
      {"state/ahead/landing", "\"/landing\" given with another timing"},
  };
  for (const auto& [name, what] : cases) {
    const std::string e = error_of(name);
    EXPECT_THAT(e, HasSubstr("feature map \"" + std::string(name) + "\": " + what)) << name;
    EXPECT_THAT(e, HasSubstr("each once and in this order")) << "the grammar, in one line";
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
  const History h{states, {}};
  v.label(h, a, label);
  EXPECT_EQ(label, (std::array<double, kActionDim>{221.5, 221.0, 225.0}));
  EXPECT_EQ(v.action(h, label), a) << "answer and label invert each other";
  base.label(h, a, label);
  EXPECT_EQ(label, (std::array<double, kActionDim>{0.5, -1.0, 2.0})) << "an impulse map answers the action";
  for (const auto& n : feature_map_names()) {
    if (n.find('/') != std::string::npos) continue;  // the base maps
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

TEST(Features, APositionMapAnswersThePoseItsServoPullsTheCupTo) {
  const FeatureMap& base = feature_map("state+clock+start_state");
  const FeatureMap& m = feature_map("state+clock+start_state/position");
  EXPECT_EQ(m.target(), ActionTarget::position);
  const std::vector<State> states{numbered(100), numbered(200)};
  const History h{states, {}};
  EXPECT_EQ(row_of(m, h), row_of(base, h));
  // numbered(200): cup x, y, angle = 200, 201, 202; vx, vy, w = 221, 222, 223.
  const Action a{0.5, -1.0, 2.0};
  std::array<double, kActionDim> label{};
  m.label(h, a, label);
  EXPECT_DOUBLE_EQ(label[0], 200.0 + (0.5 + 221.0) / kPositionGain);
  EXPECT_DOUBLE_EQ(label[2], 202.0 + (2.0 + 223.0) / kPositionGain);
  const Action back = m.action(h, label);
  for (std::size_t k = 0; k < kActionDim; ++k) EXPECT_NEAR(back[k], a[k], 1e-9) << k;
  // A tracker's action v_ref + gain (p_ref - p) - v, taken anywhere, has one label: the point
  // p_ref + v_ref / gain. So DART's noise leaves a path follower's labels unchanged.
  const double p_ref = 3.0, v_ref = 1.5;
  for (double p : {2.5, 3.0, 3.7}) {
    std::vector<State> at{numbered(0), numbered(0)};
    at[1][state_index::kCupX] = p;
    at[1][state_index::kCupVx] = -0.4 * p;
    const History hp{at, {}};
    const Action tracked{v_ref + kPositionGain * (p_ref - p) - at[1][state_index::kCupVx], 0.0, 0.0};
    m.label(hp, tracked, label);
    EXPECT_NEAR(label[0], p_ref + v_ref / kPositionGain, 1e-12) << p;
  }
  for (const auto& n : feature_map_names()) {
    if (n.find('/') != std::string::npos) continue;
    EXPECT_EQ(feature_map(n + std::string(kPositionTargetSuffix)).width(), feature_map(n).width()) << n;
    EXPECT_EQ(feature_map(n + std::string(kPositionTargetSuffix) + std::string(kAheadSuffix)).target(),
              ActionTarget::position) << n;
  }
}

TEST(Features, ADiceFrameMapSeesTheSameSceneMovedInXAsTheSame) {
  // The whole scene, start and now, moved 0.37 m in x: every input but the origin and every
  // pose answer stay as they were; the origin is the start's mean die x.
  const std::vector<State> states{numbered(100), numbered(200)};
  std::vector<State> moved = states;
  const double dx = 0.37;
  for (State& s : moved) {
    s[state_index::kCupX] += dx;
    for (std::size_t i = 0; i < kDiceCount; ++i) s[state_index::die(i)] += dx;
  }
  // Under an action delay the cup is moved ahead through what is pending: as free flight, the
  // same motion wherever the scene is.
  const std::vector<Action> pending{{0.3, -0.2, 0.1}, {-0.1, 0.4, 0.0}};
  const History h{states, {}, pending}, hm{moved, {}, pending};
  const double origin = (103.0 + 109.0 + 115.0) / 3.0;  // numbered(100)'s die x: 103, 109, 115
  for (const auto* name : {"state+clock+start_state@dice", "state+clock+start_state@dice/position",
                           "state+clock+start_state@dice/velocity", "state+clock+start_state@dice/position/ahead",
                           "clock+start_state@dice/position"}) {
    const FeatureMap& m = feature_map(name);
    const std::string base(name, std::string_view(name).find('@'));
    const auto row = row_of(m, h), row_moved = row_of(m, hm);
    ASSERT_EQ(row.size(), feature_map(base).width() + 1) << name;
    EXPECT_EQ(m.column_names().back(), "origin_x");
    EXPECT_DOUBLE_EQ(row.back(), origin) << name;
    EXPECT_DOUBLE_EQ(row_moved.back(), origin + dx) << name;
    for (std::size_t j = 0; j + 1 < row.size(); ++j) EXPECT_NEAR(row[j], row_moved[j], 1e-9) << name << " column " << j;
    const std::size_t start_x = base.starts_with("state") ? kStateDim + 1 : 1;  // after the state and t, or t
    EXPECT_DOUBLE_EQ(row[start_x], 100.0 - origin) << name << ": the start's cup x is measured from the origin";
    if (!m.ahead() && base.starts_with("state")) {
      EXPECT_DOUBLE_EQ(row[0], 200.0 - origin) << name;
    }
    const Action a{0.5, -1.0, 2.0};
    std::array<double, kActionDim> label{}, label_moved{};
    m.label(h, a, label);
    m.label(hm, a, label_moved);
    for (std::size_t k = 0; k < kActionDim; ++k) EXPECT_NEAR(label[k], label_moved[k], 1e-9) << name << " " << k;
    const Action back = m.action(hm, label_moved);
    for (std::size_t k = 0; k < kActionDim; ++k) EXPECT_NEAR(back[k], a[k], 1e-9) << name << " " << k;
  }
  // The map without the frame answers a pose in the world's x: the moved scene's label moves.
  const FeatureMap& world = feature_map("state+clock+start_state/position");
  std::array<double, kActionDim> label{}, label_moved{};
  world.label(h, {0.5, -1.0, 2.0}, label);
  world.label(hm, {0.5, -1.0, 2.0}, label_moved);
  EXPECT_NEAR(label_moved[0] - label[0], dx, 1e-12);
}

TEST(Features, ARetryMapRestartsItsClockAndStartWhenAFailedAttemptHasRested) {
  // Dice side by side on the table, the cup away: moving for 80 steps, then at rest (a failed
  // attempt) from step 80, so an attempt begins at step 89 (attempt_start). Until then the
  // "+retry" map is its base map; from then on it is the base map of the history cut at 89.
  State rest{};
  rest[state_index::kCupX] = 7.5;
  rest[state_index::kCupY] = 3.0;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    rest[state_index::die(i)] = 3.0 + 0.45 * static_cast<double>(i);
    rest[state_index::die(i) + 1] = 1.2;
  }
  std::vector<State> states;
  for (int t = 0; t < 120; ++t) {
    State s = rest;
    s[state_index::kCupX] -= 0.01 * t;  // the cup moves on: rows differ step to step
    if (t < 80) s[state_index::die(1) + 3] = 0.5 + 0.01 * t;
    if (t >= 89) s[state_index::die(2)] += 0.001 * (t - 89);  // a die nudged after the restart
    s[state_index::die(2) + 3] = t >= 89 ? 0.01 : s[state_index::die(2) + 3];
    states.push_back(s);
  }
  ASSERT_EQ(attempt_start(states, WorldConfig{}), 89u);
  for (const auto* name : {"state+clock+start_state@dice+retry", "state+clock+start_state@dice+retry/position"}) {
    const FeatureMap& m = feature_map(name);
    const FeatureMap& base = feature_map(std::string(name).replace(std::string(name).find("+retry"), 6, ""));
    ASSERT_EQ(m.width(), base.width()) << name;
    for (const std::size_t t : {0u, 50u, 88u, 89u, 90u, 119u}) {
      const History h{std::span<const State>(states.data(), t + 1), {}};
      const std::size_t from = t >= 89 ? 89 : 0;
      const History cut{std::span<const State>(states.data() + from, t + 1 - from), {}};
      EXPECT_EQ(row_of(m, h), row_of(base, cut)) << name << " t " << t;
      const Action a{0.5, -1.0, 2.0};
      std::array<double, kActionDim> label{}, label_cut{};
      m.label(h, a, label);
      base.label(cut, a, label_cut);
      EXPECT_EQ(label, label_cut) << name << " t " << t;
    }
    const History late{states, {}};
    EXPECT_EQ(row_of(m, late)[kStateDim], 30.0) << "the clock counts from the attempt's start";
    EXPECT_NE(row_of(m, late), row_of(base, late));
  }
}

TEST(Features, AnAheadMapWithNothingPendingIsItsBaseMap) {
  const std::vector<State> states{numbered(100), numbered(200)};
  const History h{states, {}};
  int maps = 0;
  for (const auto& n : feature_map_names()) {
    for (const std::string_view suffix : {kAheadSuffix, kLandingSuffix}) {
      if (!n.ends_with(suffix)) continue;
      const FeatureMap& ahead = feature_map(n);
      const FeatureMap& base = feature_map(n.substr(0, n.size() - suffix.size()));
      EXPECT_TRUE(ahead.ahead()) << n;
      EXPECT_FALSE(base.ahead()) << n;
      EXPECT_EQ(ahead.target(), base.target()) << n;
      EXPECT_EQ(row_of(ahead, h), row_of(base, h)) << n;
      ++maps;
    }
  }
  EXPECT_EQ(maps * 3, static_cast<int>(feature_map_names().size()) * 2) << "every map has its /ahead and /landing twins";
}

TEST(Features, ALandingMapShowsTheClockOfTheStepItsActionLandsAt) {
  // Two choices pending: the action chosen now runs at t + 2. Everything else is the /ahead row.
  const std::vector<State> states{numbered(100), numbered(200)};
  const std::vector<Action> pending{{1.0, 0.0, 0.0}, {0.0, 2.0, 0.5}};
  const History h{states, {}, pending};
  const FeatureMap& landing = feature_map("state+clock+start_state@dice/position/landing");
  const FeatureMap& ahead = feature_map("state+clock+start_state@dice/position/ahead");
  const auto row = row_of(landing, h), ahead_row = row_of(ahead, h);
  ASSERT_EQ(row.size(), ahead_row.size());
  EXPECT_EQ(landing.column_names(), ahead.column_names());
  for (std::size_t j = 0; j < row.size(); ++j) EXPECT_EQ(row[j], j == kStateDim ? 3.0 : ahead_row[j]) << j;
  EXPECT_EQ(ahead_row[kStateDim], 1.0);
  // Under an observation delay alone nothing is pending: the clock is the step now.
  const std::vector<Action> unseen{{1.0, 0.0, 0.0}};
  EXPECT_EQ(row_of(landing, History{states, {}, {}, unseen})[kStateDim], 1.0);
}

TEST(Features, AnAheadMapShowsTheCupWhereThePendingActionsTakeIt) {
  const std::vector<State> states{numbered(100), numbered(200)};
  const std::vector<Action> pending{{1.0, 0.0, 0.0}, {0.0, 2.0, 0.5}};
  const History h{states, {}, pending};
  const FeatureMap& m = feature_map("state+clock/velocity/ahead");
  const State s = cup_ahead(h);
  EXPECT_EQ(row_of(m, h)[kStateDim], 1.0) << "the clock counts the choices made so far";
  for (std::size_t k = 0; k < kStateDim; ++k) EXPECT_EQ(row_of(m, h)[k], s[k]) << k;
  EXPECT_EQ(s[state_index::kCupVx], 221.0 + 1.0);
  EXPECT_EQ(s[state_index::kCupW], 223.0 + 0.5);
  EXPECT_NE(s[state_index::kCupX], states[1][state_index::kCupX]);
  for (std::size_t i = 0; i < kDiceCount; ++i) EXPECT_EQ(s[state_index::die(i)], states[1][state_index::die(i)]);
  // Its velocity target is the velocity set where the action lands.
  std::array<double, kActionDim> label{};
  const Action a{0.5, -1.0, 2.0};
  m.label(h, a, label);
  EXPECT_DOUBLE_EQ(label[0], s[state_index::kCupVx] + 0.5);
  EXPECT_EQ(m.action(h, label), a);
}

TEST(Features, CupAheadIsWhereTheSimulatorTakesACupInTheAir) {
  const WorldConfig w;
  State s = random_start_state(w, 3);
  s[state_index::kCupY] += 0.3;  // clear of the table and the dice
  DiceEnv env(w);
  env.reset_to(s, 1);
  const std::vector<Action> run{{0.2, 0.1, 0.0}, {-0.1, 0.3, 0.05}, {0.0, 0.0, -0.05}};
  for (const Action& a : run) env.step(a);
  const std::vector<State> shown{s};
  const State ahead = cup_ahead(History{shown, {}, run});
  const State real = env.get_state();
  for (auto k : {state_index::kCupX, state_index::kCupY, state_index::kCupAngle, state_index::kCupVx,
                 state_index::kCupVy, state_index::kCupW})
    EXPECT_NEAR(ahead[k], real[k], 1e-4) << k;
}

TEST(Features, DatasetRowsOfAnAheadMapRunThroughTheEpisodesOwnDelay) {
  Episode e;
  e.name = "episode_0000";
  e.states = {numbered(0), numbered(1), numbered(2)};
  e.actions = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}, {0.7, 0.8, 0.9}};
  e.sources.assign(3, StepSource::expert);
  e.perturbation = R"({"action_delay": 2})";
  const FeatureMap& m = feature_map("state+clock/ahead");
  const Dataset d = make_dataset({e}, m);
  for (std::size_t t = 0; t < 3; ++t) {
    std::vector<Action> pending;
    for (std::size_t k = 0; k < 2; ++k) pending.push_back(t + k >= 2 ? e.actions[t + k - 2] : Action{0.0, 0.0, 0.0});
    const History h{std::span<const State>(e.states.data(), t + 1), {}, pending};
    EXPECT_EQ(d.x(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(kStateDim)), static_cast<double>(t));
    const State s = cup_ahead(h);
    for (std::size_t k = 0; k < kStateDim; ++k)
      EXPECT_EQ(d.x(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(k)), s[k]) << t << " " << k;
  }
  EXPECT_NE(make_dataset({e}, m).x(2, 0), make_dataset({e}, feature_map("state+clock")).x(2, 0))
      << "the base map shows the cup as recorded";
  e.perturbation = R"({"dice_mass": 0.5})";  // nothing but physics: the rows as recorded
  EXPECT_EQ(make_dataset({e}, m).x, make_dataset({e}, feature_map("state+clock")).x);
  e.perturbation = R"({"action_delay": 2.5})";
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, m); }), HasSubstr("\"action_delay\""));
  e.perturbation = R"({"observation_noise_std": [0.1]})";
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, m); }), HasSubstr("\"observation_noise_std\" must be 24"));
  e.perturbation = R"({"action_noise_std": [0.1, 0, 0]})";  // shows in no row by itself
  EXPECT_NO_THROW(make_dataset({e}, feature_map("state")));
  std::string zeros;
  for (std::size_t k = 0; k + 1 < kStateDim; ++k) zeros += "0, ";
  e.perturbation = R"({"observation_noise_std": [)" + zeros + "0.1]}";
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, feature_map("state")); }), HasSubstr("no \"noise_seed\""));
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, feature_map("state")); }), HasSubstr("episode_0000"));
  e.perturbation = R"({"action_delay": 1000000000000})";  // a user's file: bounded, not allocated
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, m); }), HasSubstr("in [0, 100]"));
  // A step a learner took (DAgger) records the expert's label, not what was pending.
  e.perturbation = R"({"action_delay": 2})";
  e.sources[1] = StepSource::policy;
  EXPECT_THAT(test::error_of([&] { make_dataset({e}, m); }), HasSubstr("steps a learner chose"));
  EXPECT_NO_THROW(make_dataset({e}, feature_map("state+clock"))) << "a map that reads no pending actions";
}

TEST(Features, AheadMapsRefuseAWorldWhosePhysicsTheyDoNotPredict) {
  WorldConfig w;
  EXPECT_NO_THROW(check_map_world(feature_map("state/ahead"), w));
  w.physics.gravity.y = -9.81;
  EXPECT_THAT(test::error_of([&] { check_map_world(feature_map("state/ahead"), w); }), HasSubstr("default world's physics"));
  EXPECT_NO_THROW(check_map_world(feature_map("state"), w));
  w = WorldConfig{};
  w.physics.substeps = 8;
  EXPECT_THAT(test::error_of([&] { check_map_world(feature_map("state+clock/velocity/ahead"), w); }),
              HasSubstr("state+clock/velocity/ahead"));
  EXPECT_THAT(test::error_of([&] { check_map_world(feature_map("state+clock/position/landing"), w); }),
              HasSubstr("use the map without \"/landing\""));
}

}  // namespace
}  // namespace dicestack
